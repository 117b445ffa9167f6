// The table of a sweep (docs/sweeps.md): one row per sweep row, the metric columns of
// `bimart eval`, the paper's number beside each of ours. Written as DIR/table.md,
// table.csv, table.json and, when gnuplot is installed, table.png (one panel per metric,
// ours against the paper's). Rows whose evaluation is not finished show "–".
#pragma once

#include <map>
#include <optional>
#include <string>
#include <vector>

#include "core/sweep/plan.h"

namespace bimart::sweep {

struct TableRow {
  std::string name, section;
  std::map<std::string, double> ours;   // metric column -> value (absent: not measured)
  std::map<std::string, double> paper;
  std::string run_key;                   // the generate job that made the samples
  double seconds = 0;                    // wall time of its jobs (train jobs not included)
};

// The rows of `plan` with the metrics of every finished evaluation.
std::vector<TableRow> collect_table(const Plan& plan);

std::string table_markdown(const Plan& plan, const std::vector<TableRow>& rows);
std::string table_csv(const std::vector<TableRow>& rows);

struct TableFiles {
  std::vector<std::string> written;
  std::string picture_note;  // why there is no picture, when there is none
};
// Writes DIR/table.{md,csv,json} and table.png; `gnuplot` is the program to draw with.
TableFiles write_table(const Plan& plan, const std::string& gnuplot = "gnuplot");

}  // namespace bimart::sweep
