// The plan of the change report's page (report_html.cc): an SVG in the world frame, north up when the
// flight has GPS.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "patrolmap/change/report.h"

namespace patrolmap::change {

// Both flights' paths (the current one solid, the prior one dashed), the places both saw, the changed
// geometry's outlines, each change as a numbered marker (class "marker", data-id its id), a scale bar, and
// with `geo` a latitude/longitude grid and a north arrow. Empty when nothing has a position.
std::string PlanSvg(const ChangeReport& report, const graph::TopoMap& map, const std::vector<ChangeItem>& items,
                    const std::optional<GeoReference>& geo);

// The colour of a change's marker and row: by kind and state.
const char* ChangeColour(const ChangeItem& item);

}  // namespace patrolmap::change
