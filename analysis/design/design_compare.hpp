#pragma once
// Design against flying (SPEC §7): signed distance of every flying point to the
// design surface, its statistics, and per-section parameter deltas at the same
// fractions. Both shapes must be in the boat frame, in metres.
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "analysis/core/cloud.hpp"
#include "analysis/core/mesh.hpp"
#include "analysis/core/progress.hpp"
#include "analysis/outline/sail_outline.hpp"
#include "analysis/sections/sections.hpp"

namespace sailshape {

// Closest points on a design mesh, with the sign of the side. The sail's
// leeward side is the side its camber bulges to: the mesh's boundary loop(s)
// span a best-fit plane, and the area of the mesh lies on the leeward side of
// it. A point on that side of the surface has a positive distance.
class DesignDistance {
 public:
  // Throws InvalidInput for a mesh without triangles or with an index out of range.
  explicit DesignDistance(const Mesh& design);
  ~DesignDistance();
  DesignDistance(const DesignDistance&) = delete;
  DesignDistance& operator=(const DesignDistance&) = delete;

  struct Closest {
    Vec3 point = Vec3::Zero();  // on the design surface
    uint32_t triangle = 0;
    double distance_m = 0;      // signed: positive to leeward
  };
  Closest closest(const Vec3& p) const;
  double signedDistance(const Vec3& p) const { return closest(p).distance_m; }

  // Unit normal of the boundary's best-fit plane, pointing to leeward.
  const Vec3& leeward() const { return leeward_; }
  // False when the design is (nearly) flat: the sign then follows `leeward()`
  // chosen towards +Y (port), and a warning says so.
  bool cambered() const { return cambered_; }
  const std::vector<std::string>& warnings() const { return warnings_; }

 private:
  struct Index;
  std::vector<Vec3> a_, b_, c_;   // triangle corners
  std::vector<Vec3> normal_;      // per triangle, unit, turned to leeward
  std::vector<Vec3> centroid_;
  Vec3 leeward_ = Vec3::UnitY();
  bool cambered_ = true;
  std::vector<std::string> warnings_;
  std::unique_ptr<Index> index_;
};

// Closest point to p on triangle (a, b, c) (Ericson, Real-Time Collision Detection §5.1.5).
Vec3 closestPointOnTriangle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c);

struct DistanceStats {
  size_t count = 0;
  double mean_m = 0, rms_m = 0, max_abs_m = 0;
  double p5_m = 0, p50_m = 0, p95_m = 0;  // percentiles of the signed distance (linear interpolation)
};

// Throws InvalidInput for an empty list.
DistanceStats distanceStats(const std::vector<double>& signed_distances_m);

// Signed distance of each point to the design, in the points' order.
std::vector<double> signedDistances(const DesignDistance& design, const std::vector<Vec3>& points,
                                    const Progress& progress = {});

// How a mesh is prepared for the outline and section analysis. The outline
// finds where a *sampled* surface really ends by assuming its boundary points
// sit at random distances inside the true edge; an exact mesh breaks that
// assumption (a generated 80 × 40 design's corners land 10–20 cm out, and a
// regular grid's edges one column spacing out), and coarse exports give too few
// boundary points (Sailcut's Star45 jib: 130 boundary edges). So a mesh is by
// default sampled uniformly at random over its area and the samples are meshed
// by the pipeline's surface step (SPEC §4 step 5), as a clean scan would be.
struct MeshSampling {
  // "resample": always (default); "mesh": analyse the mesh as it is; "auto":
  // resample when it has more than one boundary loop or fewer than
  // `min_boundary_edges` boundary edges.
  std::string mode = "resample";
  size_t min_boundary_edges = 200;
  size_t points = 150'000;
  uint64_t seed = 1;
};

// The mesh sampled uniformly as `sampling` says (points, seed) and meshed again by the
// pipeline's surface step, projected on its best-fit plane, as a clean scan would be.
Mesh resampleMesh(const Mesh& mesh, const MeshSampling& sampling = {});

// Outline and sections of a mesh (a design, or a flying shape given as a mesh).
struct MeshSections {
  SailOutline outline;
  SectionAnalysis sections;
  bool resampled = false;
  std::vector<std::string> notes;  // e.g. why the mesh was resampled
};
// Throws InvalidInput for an unknown sampling mode, and what extractOutline and
// cutSections throw.
MeshSections analyzeMeshSections(const Mesh& mesh, const OutlineParams& outline = {},
                                 const SectionParams& sections = {}, const MeshSampling& sampling = {});

// Number of boundary edges (used by one triangle) and of boundary loops.
struct BoundaryCount {
  size_t edges = 0, loops = 0;
};
BoundaryCount countBoundary(const Mesh& mesh);

// `points` samples spread uniformly over the mesh's area (fixed seed).
Cloud sampleMesh(const Mesh& mesh, size_t points, uint64_t seed = 1);

// How far from its design a sail may fly at a plausible trim, m: 0.2 × the design's
// mean chord (area over height). Trim moves the cloth by a camber change (±5 % of the
// chord, at the deepest point), by twist (±10° at the head about the luff: the leech
// moves chord × sin 10° = 0.17 chord) and by the sheeting angle; together up to about a
// fifth of the chord at the leech, less on average over the sail. Another sail, a wall
// or the wrong side of a tunnel lies a whole chord or more away. Throws InvalidInput
// for a design without area or height.
double plausibleTrimDeviationM(const Mesh& design);

struct SectionDelta {
  double fraction = 0;
  SectionParameters design, flying;
  SectionParameters delta;  // flying − design, field by field
};

// Pairs the sections at the same fractions; a section unmeasured in either
// analysis has no delta, and twist_rel is taken from the lowest section both
// measured. Throws InvalidInput when the two analyses were not asked for the same
// fractions.
std::vector<SectionDelta> sectionDeltas(const SectionAnalysis& design, const SectionAnalysis& flying);

struct DesignComparison {
  std::vector<double> distance_m;  // per flying point, signed, positive to leeward
  DistanceStats stats;
  Vec3 leeward = Vec3::UnitY();    // the design's leeward normal
  std::vector<SectionDelta> sections;
  std::vector<std::string> warnings;
};

// Everything at once: distances of `flying_points` to `design`, and deltas of
// `flying_sections` against `design_sections`.
DesignComparison compareWithDesign(const Mesh& design, const SectionAnalysis& design_sections,
                                   const std::vector<Vec3>& flying_points, const SectionAnalysis& flying_sections,
                                   const Progress& progress = {});

}  // namespace sailshape
