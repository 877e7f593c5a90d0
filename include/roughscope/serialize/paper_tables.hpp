// The paper's Tables 1–3 recomputed from their printed inputs with the §4 estimators, next to
// the printed values (Eq. 13 and 15 for Table 1, Eq. 17 and 19 with Caron's θK and ξK for
// Table 2, Eq. 17 and 19 for Table 3). The printed values come from a JSON document with the
// layout of ../shared/reference/paper-tables.json (never part of the repository).
//
// Each recomputed quantity is an object {printed, recomputed, rounding_interval, agreement}:
//   exact            rounds to the printed value at the printed number of decimals;
//   within_rounding  the printed value lies in the range the recomputation spans when the
//                    printed inputs vary over their rounding interval (± half a unit of their
//                    last digit; the estimators are monotonic in each input, so the corners of
//                    that box bound it), widened by half a unit of the output's last digit;
//   differs          neither.
// The command line (`roughscope paper tables`) and the Python report both show this document.
#pragma once

#include <filesystem>
#include <string>

#include "roughscope/serialize/json.hpp"

namespace roughscope::serialize {

// {"table1": {"conditions", "rows"}, "table2": ..., "table3": ...}. Throws DataError
// "<where>: <place in the document>: <what>" for a missing or malformed key (places as
// "table1_slightly_rough.rows[0].R_spec", io's JSON reader) or a printed input the estimators
// refuse.
Json recompute_paper_tables(const Json& reference, const std::string& where);

// Reads the reference document (docs/input-files.md: UTF-8 BOM, CRLF accepted). Throws DataError
// "<path>: does not exist", "<path>: is a directory, not a file", "<path>: line L, column C: not
// a text file: NUL byte" or "<path>: line L, column C: not valid JSON: <what>".
Json read_paper_tables_reference(const std::filesystem::path& path);

// The text report of `roughscope paper tables` (without --json): the three tables of the
// document recompute_paper_tables returns, each quantity as printed, recomputed (*) and its mark
// (= exact, ~ within rounding, DIFFERS).
std::string paper_tables_text(const Json& tables);

}  // namespace roughscope::serialize
