#pragma once
// The design as a prior for the analysis (issue 37): a scan that did not reach every corner
// (the head out of range, the top seen at grazing angles) has no luff or leech length of its
// own, so no section can be placed on it alone. With the sail's design fitted onto the samples
// (analysis/fit), the corners the scan did not reach and the surface beyond its last samples
// are the fitted design's, and each section's σ carries the fit's own where its curve runs
// over inferred surface.
#include "analysis/core/cloud.hpp"
#include "analysis/core/mesh.hpp"
#include "analysis/core/progress.hpp"
#include "analysis/design/design_compare.hpp"
#include "analysis/pipeline/pipeline.hpp"
#include "analysis/pipeline/sail_region.hpp"

namespace sailshape {

// analyzeInRegion; and when that refuses after the sail's surface was built (a corner not
// reached, no outline on a patch of the sail), or when it measured a luff or leech shorter than
// its design's by more than stretch and tension explain (it stopped short of a head it could
// not tell it missed: no scanner position, a crop), the analysis of the design fitted onto the
// sail's samples: a.design_fit holds the fit and a.inferred_because the scan's refusal;
// a.mesh and a.sail_cloud stay the scan's; a.outline has the corners the scan reached where
// it measured them and the others from the fitted design, a.outline.coverage says which;
// a.sections are cut on the fitted surface, each with the share of its curve that was
// inferred. `design_sections`: the design's own outline and sections (analyzeMeshSections,
// asked for the same fractions as params.sections): where the flying sail was not seen it
// differs from them by no more than a plausible trim, which bounds the inferred values' σ.
// Throws what analyzeInRegion throws before the surface exists, and AnalysisError when the
// design does not fit the samples either.
SailAnalysis analyzeWithDesign(const Cloud& scan, const RegionBox& region, const Mesh& design,
                               const MeshSections& design_sections, const AnalysisParams& params,
                               const Progress& progress = {});

}  // namespace sailshape
