#pragma once
// The JSON document of `sailshape analyze --json` (keys carry units: _m, _deg, _pct).
#include <nlohmann/json_fwd.hpp>
#include <vector>

#include "analysis/pipeline/pipeline.hpp"

namespace sailshape {

nlohmann::json sectionParametersToJson(const SectionParameters& p);
nlohmann::json sectionToJson(const Section& s);
// The sections asked for but not measured: [{fraction, reason}, ...].
nlohmann::json unmeasuredSectionsToJson(const std::vector<UnmeasuredSection>& unmeasured);
nlohmann::json analysisToJson(const SailAnalysis& analysis);

}  // namespace sailshape
