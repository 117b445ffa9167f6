#include "core/trajectory/csv_trajectory.h"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <vector>

#include "core/trajectory/validation.h"
#include "core/util/text.h"

namespace bimart {

namespace {

std::string trim(const std::string& s) {
  const auto b = s.find_first_not_of(" \t\r");
  if (b == std::string::npos) return "";
  return s.substr(b, s.find_last_not_of(" \t\r") - b + 1);
}

std::vector<std::string> split(const std::string& line) {
  std::vector<std::string> out;
  std::size_t start = 0;
  for (;;) {
    const std::size_t comma = line.find(',', start);
    out.push_back(trim(line.substr(start, comma == std::string::npos ? std::string::npos : comma - start)));
    if (comma == std::string::npos) return out;
    start = comma + 1;
  }
}

// The whole field as a number, or an error naming it.
double parse_number(const std::string& field, const SourceLocation& at, const std::string& column) {
  if (field.empty()) throw Error(at, "column '" + column + "' is empty");
  errno = 0;
  char* end = nullptr;
  const double v = std::strtod(field.c_str(), &end);
  if (end != field.c_str() + field.size())
    throw Error(at, "column '" + column + "': '" + field + "' is not a number");
  if (!std::isfinite(v)) throw Error(at, "column '" + column + "': '" + field + "' is not a finite number");
  return v;
}

}  // namespace

Trajectory read_csv_trajectory(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw Error(path + ": cannot open the trajectory file");
  // The seven state columns, then two optional ones: frame (ignored) and time (seconds).
  static const std::vector<std::string> names = {"angle", "rx", "ry", "rz", "tx", "ty", "tz", "frame", "time"};
  Trajectory tr;
  tr.file = path;
  std::vector<int> column;  // file column -> state index
  std::vector<std::array<double, 9>> rows;
  std::string raw;
  int line = 0;
  while (std::getline(in, raw)) {
    ++line;
    const SourceLocation at{path, line, 0};
    const std::string text = trim(raw);
    if (text.empty()) continue;
    if (text[0] == '#') {
      const std::string body = trim(text.substr(1));
      const auto colon = body.find(':');
      if (colon == std::string::npos) continue;
      const std::string key = trim(body.substr(0, colon)), value = trim(body.substr(colon + 1));
      if (key == "fps") {
        tr.fps = parse_number(value, at, "fps");
        if (!(tr.fps > 0)) throw Error(at, fmt::format("fps must be positive, got {}", value));
      } else if (key == "object" || key == "category") {
        (key == "object" ? tr.object.path : tr.object.category) = value;
        tr.object.where = at;
      } else if (key == "seed") {
        const double s = parse_number(value, at, "seed");
        if (s < 0 || s != std::floor(s) || s > 1e15) throw Error(at, "seed must be a whole number >= 0, got " + value);
        tr.object.seed = static_cast<std::int64_t>(s);
      }
      continue;
    }
    const std::vector<std::string> fields = split(text);
    if (column.empty()) {  // the header
      std::array<int, 9> seen{};
      for (const std::string& f : fields) {
        int k = 0;
        while (k < 9 && names[k] != f) ++k;
        if (k == 9)
          throw Error(at, "unknown column '" + f + "' in the header" + did_you_mean(f, names) +
                              " (the header names angle, rx, ry, rz, tx, ty, tz; optionally frame, time)");
        if (seen[k]++) throw Error(at, "column '" + f + "' is named twice in the header");
        column.push_back(k);
      }
      for (int k = 0; k < 7; ++k)
        if (!seen[k]) throw Error(at, "the header has no column '" + names[k] + "' (it needs angle, rx, ry, rz, tx, ty, tz)");
      continue;
    }
    if (fields.size() != column.size())
      throw Error(at, fmt::format("this row has {} values; the header names {}", fields.size(), column.size()));
    if (static_cast<std::int64_t>(rows.size()) >= kMaxTrajectoryFrames)
      check_frame_count(kMaxTrajectoryFrames + 1, at, "the rows up to this line");
    std::array<double, 9> row{};
    for (std::size_t i = 0; i < fields.size(); ++i) row[column[i]] = parse_number(fields[i], at, names[column[i]]);
    rows.push_back(row);
    tr.lines.push_back({line, 0});
  }
  if (column.empty()) throw Error(path + ": no header line (angle,rx,ry,rz,tx,ty,tz) and no rows");
  check_frame_count(static_cast<std::int64_t>(rows.size()), SourceLocation{path, line, 0},
                    fmt::format("{} rows", rows.size()));
  const bool timed = std::find(column.begin(), column.end(), 8) != column.end();
  if (timed) {  // evenly spaced times give the frame rate (or must agree with `# fps:`)
    const double step = (rows.back()[8] - rows.front()[8]) / static_cast<double>(rows.size() - 1);
    for (std::size_t r = 1; r < rows.size(); ++r) {
      const double dt = rows[r][8] - rows[r - 1][8];
      if (!(dt > 0) || std::abs(dt - step) > 0.01 * step)
        throw Error(SourceLocation{path, tr.lines[r][0], 0},
                    fmt::format("column 'time': rows must be evenly spaced in time ({:.6g} s apart on average), "
                                "but this row comes {:.6g} s after the previous one",
                                step, dt));
    }
    if (tr.fps > 0 && std::abs(1 / step - tr.fps) > 0.01 * tr.fps)
      throw Error(SourceLocation{path, tr.lines[1][0], 0},
                  fmt::format("column 'time' steps by {:.6g} s ({:.6g} fps) but the file says fps: {}", step, 1 / step,
                              tr.fps));
    if (!(tr.fps > 0)) tr.fps = 1 / step;
  }
  tr.states.resize(static_cast<Eigen::Index>(rows.size()), 7);
  for (std::size_t r = 0; r < rows.size(); ++r)
    for (int k = 0; k < 7; ++k) tr.states(static_cast<Eigen::Index>(r), k) = rows[r][k];
  return tr;
}

}  // namespace bimart
