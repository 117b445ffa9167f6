#include "core/sweep/table.h"

#include <sys/wait.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "core/sweep/job_state.h"
#include "core/util/atomic_file.h"
#include "core/util/text.h"

namespace bimart::sweep {
namespace {

namespace fs = std::filesystem;
using json = nlohmann::json;

struct Column {
  const char* unit;
  bool higher_is_better;
  int decimals;
};

Column column_info(const std::string& name) {
  if (name == "Mul") return {"cm", true, 2};
  if (name == "Accel") return {"", false, 3};
  if (name == "CM") return {"cm", false, 2};
  if (name == "Depth") return {"mm", false, 2};
  if (name == "Con" || name == "Art") return {"%", true, 2};
  return {"%", false, 2};  // Pen 1cm, Pen 5mm, Pen 3mm
}

std::string header(const std::string& m) {
  const Column c = column_info(m);
  return fmt::format("{}{}{} {}", m, *c.unit ? " " : "", c.unit, c.higher_is_better ? "↑" : "↓");
}

std::string number(const std::map<std::string, double>& v, const std::string& m, int decimals) {
  const auto it = v.find(m);
  if (it == v.end() || !std::isfinite(it->second)) return "–";
  return fmt::format("{:.{}f}", it->second, decimals);
}

std::string csv_field(const std::string& s) {
  if (s.find_first_of(",\"\n") == std::string::npos) return s;
  std::string q = "\"";
  for (char c : s) q += c == '"' ? std::string("\"\"") : std::string(1, c);
  return q + "\"";
}

}  // namespace

std::vector<TableRow> collect_table(const Plan& plan) {
  std::vector<TableRow> rows;
  for (const auto& r : plan.rows) {
    TableRow t;
    t.name = r.name;
    t.section = r.section;
    t.paper = r.paper;
    const Job& gen = plan.jobs.at(r.generate);
    const Job& ev = plan.jobs.at(r.eval);
    t.run_key = gen.key;
    if (is_done(ev)) {
      std::ifstream in(ev.result);
      const json j = json::parse(in, nullptr, false);
      const json& set = j.is_discarded() ? json() : (j.contains("generated") ? j["generated"] : j);
      if (set.contains("metrics"))
        for (const auto& m : set["metrics"])
          if (m.contains("value") && m["value"].is_number()) t.ours[m.value("name", std::string())] = m["value"].get<double>();
      for (const Job* job : {&gen, &ev}) t.seconds += read_done(*job).value("seconds", 0.0);
    }
    rows.push_back(std::move(t));
  }
  return rows;
}

std::string table_markdown(const Plan& plan, const std::vector<TableRow>& rows) {
  std::string md = fmt::format("# Sweep {}\n\nFrom `{}`. Each cell: ours / the paper's. "
                               "Metrics as docs/metrics.md defines them; our data is synthetic, so the numbers "
                               "compare in spirit and the orderings are what should carry over.\n\n",
                               plan.name, plan.sweep_file);
  md += "| section | row |";
  for (const auto& m : metric_columns()) md += " " + header(m) + " |";
  md += " wall time |\n| --- | --- |";
  for (std::size_t i = 0; i < metric_columns().size(); ++i) md += " ---: |";
  md += " ---: |\n";
  for (const auto& r : rows) {
    md += fmt::format("| {} | {} |", r.section, r.name);
    for (const auto& m : metric_columns()) {
      const int d = column_info(m).decimals;
      const std::string paper = number(r.paper, m, d);
      md += " " + number(r.ours, m, d) + (paper == "–" && r.paper.empty() ? "" : " / " + paper) + " |";
    }
    md += " " + (r.seconds > 0 ? format_duration(r.seconds) : std::string("–")) + " |\n";
  }
  return md;
}

std::string table_csv(const std::vector<TableRow>& rows) {
  std::string csv = "section,row";
  for (const auto& m : metric_columns()) csv += "," + csv_field(m) + "," + csv_field(m + " (paper)");
  csv += ",seconds\n";
  for (const auto& r : rows) {
    csv += csv_field(r.section) + "," + csv_field(r.name);
    for (const auto& m : metric_columns()) {
      const auto o = r.ours.find(m);
      const auto p = r.paper.find(m);
      csv += "," + (o != r.ours.end() ? fmt::format("{}", o->second) : std::string());
      csv += "," + (p != r.paper.end() ? fmt::format("{}", p->second) : std::string());
    }
    csv += fmt::format(",{:.0f}\n", r.seconds);
  }
  return csv;
}

TableFiles write_table(const Plan& plan, const std::string& gnuplot) {
  TableFiles out;
  const auto rows = collect_table(plan);
  const fs::path dir(plan.dir);
  const auto put = [&](const std::string& name, const std::string& text) {
    write_file_atomically((dir / name).string(), [&](std::ostream& o) { o << text; });
    out.written.push_back((dir / name).string());
  };
  put("table.md", table_markdown(plan, rows));
  put("table.csv", table_csv(rows));
  json j = json::array();
  for (const auto& r : rows)
    j.push_back({{"section", r.section}, {"row", r.name}, {"ours", r.ours}, {"paper", r.paper},
                 {"run", r.run_key}, {"seconds", r.seconds}});
  put("table.json", j.dump(2) + "\n");

  // The picture: gnuplot reads a data file and a script; both stay beside the table.
  std::string dat = "row";
  for (const auto& m : metric_columns()) dat += "\t" + m + "\t" + m + " (paper)";
  dat += "\n";
  bool any = false;
  for (const auto& r : rows) {
    dat += r.name;
    for (const auto& m : metric_columns())
      for (const auto* v : {&r.ours, &r.paper}) {
        const auto it = v->find(m);
        any = any || (v == &r.ours && it != v->end());
        dat += "\t" + (it != v->end() ? fmt::format("{}", it->second) : std::string("NaN"));
      }
    dat += "\n";
  }
  put("table.dat", dat);
  if (!any) {
    out.picture_note = "no row has metrics yet";
    return out;
  }
  const std::size_t n = metric_columns().size();
  std::string gp = fmt::format(
      "# gnuplot script written by bimart sweep: gnuplot table.gp draws table.png\n"
      "set terminal pngcairo size 1800,1000 font ',10'\nset output 'table.png'\n"
      "set datafile separator '\\t'\nset datafile missing 'NaN'\n"
      "set style data histograms\nset style histogram clustered gap 1\n"
      "set style fill solid 0.85 border -1\nset key top right\nset grid ytics\n"
      "set xtics rotate by -35 left\nset yrange [0:*]\n"
      "set multiplot layout 2,{} title 'sweep {}: ours (blue) and the paper (grey)'\n",
      (n + 1) / 2, plan.name);
  for (std::size_t i = 0; i < n; ++i) {
    const std::string& m = metric_columns()[i];
    gp += fmt::format("set title '{}'\nplot 'table.dat' using {}:xtic(1) title 'ours' lc rgb '#3060c0', "
                      "'' using {} title 'paper' lc rgb '#a0a0a0'\n",
                      header(m), 2 + 2 * i, 3 + 2 * i);
  }
  gp += "unset multiplot\n";
  put("table.gp", gp);
  const std::string cmd = fmt::format("cd '{}' && '{}' table.gp > table.gp.log 2>&1", dir.string(), gnuplot);
  const int rc = std::system(cmd.c_str());
  if (rc == 0 && fs::exists(dir / "table.png")) {
    out.written.push_back((dir / "table.png").string());
  } else {
    out.picture_note = fmt::format("no picture: '{}' failed or is not installed (apt-get install gnuplot-nox); see {}",
                                   gnuplot, (dir / "table.gp.log").string());
  }
  return out;
}

}  // namespace bimart::sweep
