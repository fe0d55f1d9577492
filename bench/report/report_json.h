// The report document (results.json of `depthbench report`, kReportSchema,
// described field by field in reports/report.schema.json): the typed
// report written as JSON, numbers as the report shows them and null where
// a figure is not finite. The page embeds this document and draws it.
#pragma once

#include <nlohmann/json.hpp>

#include "bench/report/report_model.h"

namespace depthbench {

nlohmann::json ReportToJson(const Report& report);

}  // namespace depthbench
