#pragma once
// The JSON document of `sailshape analyze --json` (keys carry units: _m, _deg, _pct).
#include <nlohmann/json_fwd.hpp>
#include <vector>

#include "analysis/design/design_compare.hpp"
#include "analysis/pipeline/pipeline.hpp"

namespace sailshape {

nlohmann::json sectionParametersToJson(const SectionParameters& p);
// Per section: {"fraction", "design", "flying", "delta"}, each parameters as above.
nlohmann::json sectionDeltasToJson(const std::vector<SectionDelta>& deltas);
nlohmann::json sectionToJson(const Section& s);
// The sections asked for but not measured: [{fraction, reason}, ...].
nlohmann::json unmeasuredSectionsToJson(const std::vector<UnmeasuredSection>& unmeasured);
nlohmann::json analysisToJson(const SailAnalysis& analysis);

}  // namespace sailshape
