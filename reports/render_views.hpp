#pragma once
// Offscreen VTK pictures of a sail for the report: the design as a blue
// wireframe grid with the flying shape as a red surface, seen from the side,
// from above and from astern, and the flying shape coloured by its signed
// distance to the design. VTK stays inside render_views.cpp.
#include <array>
#include <cstdint>
#include <stdexcept>
#include <vector>

#include "analysis/core/mesh.hpp"

namespace sailshape {

struct RgbImage {
  int width = 0, height = 0;
  std::vector<uint8_t> rgb;  // width × height × 3, top row first
};

using Rgb = std::array<double, 3>;  // components in [0, 1]

inline constexpr Rgb kDesignBlue{0.10, 0.25, 0.85};
inline constexpr Rgb kFlyingRed{0.85, 0.12, 0.10};

// Diverging colour of a signed distance: blue (−range, to windward) through
// white (0) to orange-red (+range, to leeward); clamped outside ±range.
Rgb deviationColour(double distance_m, double range_m);

struct PictureSize {
  int width_px = 600, height_px = 600;
};

// Each view is framed to fill its picture: the sail is tall from the side and
// astern, and long and thin from above.
struct RenderParams {
  PictureSize side{570, 990}, top{750, 570}, astern{270, 990}, deviation{570, 990};
  double deviation_range_m = 0.05;  // the colour map's ± limit
};

struct SailViews {
  RgbImage side, top, astern;  // design wireframe + flying surface
  RgbImage deviation;          // flying surface coloured by deviation, side view
};

// `deviation_m` holds one signed distance per vertex of `flying` (positive to
// leeward). Needs an X display (see private_display.hpp). Throws InvalidInput
// for empty meshes or a deviation list of the wrong length, RenderError when
// VTK gives no picture.
SailViews renderSailViews(const Mesh& design, const Mesh& flying, const std::vector<double>& deviation_m,
                          const RenderParams& params = {});

// The side view of `mesh` coloured per vertex by `values` (deviationColour over ±range);
// vertices flagged in `muted` are drawn pale, blended three quarters towards light grey (what
// was inferred rather than measured). Throws as renderSailViews does, and InvalidInput for a
// value or flag list of the wrong length.
RgbImage renderColouredSide(const Mesh& mesh, const std::vector<double>& values, double range,
                            const std::vector<char>& muted, const PictureSize& size);

// The colour a muted vertex is drawn in.
Rgb mutedColour(const Rgb& colour);

struct RenderError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// Edges of a triangle mesh for a wireframe "grid": an edge shared by two
// triangles that is the longest edge of both (a quad's diagonal) is left out.
std::vector<std::array<uint32_t, 2>> gridEdges(const Mesh& mesh);

}  // namespace sailshape
