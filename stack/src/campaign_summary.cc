#include "stewart/stack/campaign_summary.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <limits>
#include <sstream>

#include "stewart/common/check.h"

namespace stewart {
namespace {

using nlohmann::json;

std::vector<std::string> SplitCsvLine(const std::string& line) {
  std::vector<std::string> fields;
  std::string field;
  bool quoted = false;
  for (std::size_t i = 0; i < line.size(); ++i) {
    const char c = line[i];
    if (quoted) {
      if (c == '"' && i + 1 < line.size() && line[i + 1] == '"') {
        field += '"';
        ++i;
      } else if (c == '"') {
        quoted = false;
      } else {
        field += c;
      }
    } else if (c == '"') {
      quoted = true;
    } else if (c == ',') {
      fields.push_back(field);
      field.clear();
    } else {
      field += c;
    }
  }
  fields.push_back(field);
  return fields;
}

double Quantile(std::vector<double> v, double p) {
  if (v.empty()) return std::numeric_limits<double>::quiet_NaN();
  std::sort(v.begin(), v.end());
  const double pos = p * static_cast<double>(v.size() - 1);
  const auto lo = static_cast<std::size_t>(std::floor(pos));
  const std::size_t hi = std::min(lo + 1, v.size() - 1);
  return v[lo] + (pos - static_cast<double>(lo)) * (v[hi] - v[lo]);
}

json Quantiles(const std::vector<double>& v) {
  return json{{"min", Quantile(v, 0.0)},  {"p01", Quantile(v, 0.01)}, {"p05", Quantile(v, 0.05)},
              {"p50", Quantile(v, 0.50)}, {"p95", Quantile(v, 0.95)}, {"max", Quantile(v, 1.0)}};
}

bool EndsWith(const std::string& s, const std::string& suffix) {
  return s.size() >= suffix.size() &&
         s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
}

// "xd_upper" is a velocity limit, "x_upper" a position limit.
bool IsVelocityLimit(const std::string& name) {
  const std::size_t underscore = name.find('_');
  return underscore != std::string::npos && underscore >= 1 && name[underscore - 1] == 'd';
}

// Ranks (0 .. n-1, ties averaged) of `v`.
std::vector<double> Ranks(const std::vector<double>& v) {
  std::vector<std::size_t> order(v.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return v[a] < v[b]; });
  std::vector<double> rank(v.size());
  for (std::size_t i = 0; i < order.size();) {
    std::size_t j = i;
    while (j + 1 < order.size() && v[order[j + 1]] == v[order[i]]) ++j;
    for (std::size_t k = i; k <= j; ++k) rank[order[k]] = 0.5 * static_cast<double>(i + j);
    i = j + 1;
  }
  return rank;
}

// Spearman's rank correlation; NaN when either side is constant.
double RankCorrelation(const std::vector<double>& x, const std::vector<double>& y) {
  const std::vector<double> rx = Ranks(x), ry = Ranks(y);
  const double n = static_cast<double>(x.size());
  double mx = 0.0, my = 0.0;
  for (std::size_t i = 0; i < x.size(); ++i) {
    mx += rx[i] / n;
    my += ry[i] / n;
  }
  double sxy = 0.0, sxx = 0.0, syy = 0.0;
  for (std::size_t i = 0; i < x.size(); ++i) {
    sxy += (rx[i] - mx) * (ry[i] - my);
    sxx += (rx[i] - mx) * (rx[i] - mx);
    syy += (ry[i] - my) * (ry[i] - my);
  }
  return sxx > 0.0 && syy > 0.0 ? sxy / std::sqrt(sxx * syy)
                                : std::numeric_limits<double>::quiet_NaN();
}

std::string Fmt(const char* format, double v) {
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, format, v);
  return buffer;
}

}  // namespace

std::string CsvField(const std::string& s) {
  if (s.find_first_of(",\"\n") == std::string::npos) return s;
  std::string out = "\"";
  for (const char c : s) {
    if (c == '"') out += '"';
    out += c == '\n' ? ' ' : c;
  }
  return out + "\"";
}

int CsvTable::Column(const std::string& name) const {
  const auto it = std::find(header.begin(), header.end(), name);
  return it == header.end() ? -1 : static_cast<int>(it - header.begin());
}

double CsvTable::Number(std::size_t row, int column) const {
  STEWART_CHECK(column >= 0 && static_cast<std::size_t>(column) < header.size(),
                "CsvTable::Number: no such column");
  const std::string& s = rows[row][static_cast<std::size_t>(column)];
  if (s.empty()) return std::numeric_limits<double>::quiet_NaN();
  return std::stod(s);
}

CsvTable ParseCsv(const std::string& text, const std::string& source) {
  std::istringstream in(text);
  CsvTable table;
  std::string line;
  if (!std::getline(in, line)) throw InputError(source, "empty, expected a CSV header");
  table.header = SplitCsvLine(line);
  for (long n = 2; std::getline(in, line); ++n) {
    if (line.empty()) continue;
    std::vector<std::string> fields = SplitCsvLine(line);
    if (fields.size() != table.header.size()) {
      throw InputError(source + ":" + std::to_string(n), "has " + std::to_string(fields.size()) +
                                                             " fields, the header " +
                                                             std::to_string(table.header.size()));
    }
    table.rows.push_back(std::move(fields));
  }
  return table;
}

CsvTable ReadCsv(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw InputError(path, "cannot open");
  std::stringstream text;
  text << in.rdbuf();
  return ParseCsv(text.str(), path);
}

void WriteCsv(const std::string& path, const CsvTable& table) {
  std::ofstream out(path);
  if (!out) throw InputError(path, "cannot write");
  auto write = [&](const std::vector<std::string>& fields) {
    for (std::size_t i = 0; i < fields.size(); ++i) out << (i ? "," : "") << CsvField(fields[i]);
    out << '\n';
  };
  write(table.header);
  for (const auto& row : table.rows) write(row);
}

json SummarizeCampaign(const CsvTable& runs, const json& meta, double tolerance) {
  json s;
  s["campaign"] = meta;
  const std::size_t n = runs.rows.size();
  s["runs"] = n;
  s["tolerance"] = tolerance;
  const int index_col = runs.Column("index");
  const int seed_col = runs.Column("seed");
  auto run_id = [&](std::size_t r) {
    return json{{"index", std::stol(runs.rows[r][static_cast<std::size_t>(index_col)])},
                {"seed", std::stoul(runs.rows[r][static_cast<std::size_t>(seed_col)])}};
  };
  // Per limit: how often, how far, and who.
  json limits = json::array();
  std::vector<double> worst_position(n, 1e9), worst_velocity(n, 1e9);
  for (std::size_t c = 0; c < runs.header.size(); ++c) {
    const std::string& column = runs.header[c];
    if (!EndsWith(column, "_excess")) continue;
    const std::string name = column.substr(0, column.size() - 7);
    const int margin_col = runs.Column(name + "_margin");
    long exceeded = 0, beyond_tolerance = 0;
    double worst = 0.0;
    std::size_t worst_row = 0;
    for (std::size_t r = 0; r < n; ++r) {
      const double excess = runs.Number(r, static_cast<int>(c));
      if (excess > 0.0) ++exceeded;
      if (excess > tolerance) ++beyond_tolerance;
      if (excess > worst) {
        worst = excess;
        worst_row = r;
      }
      if (margin_col >= 0) {
        std::vector<double>& group = IsVelocityLimit(name) ? worst_velocity : worst_position;
        group[r] = std::min(group[r], runs.Number(r, margin_col));
      }
    }
    json entry{{"limit", name},
               {"unit", IsVelocityLimit(name) ? "m/s" : "m"},
               {"runs_exceeding", exceeded},
               {"runs_beyond_tolerance", beyond_tolerance},
               {"violation_rate", n ? static_cast<double>(beyond_tolerance) / n : 0.0},
               {"worst_excess", worst}};
    if (worst > 0.0) entry["worst_run"] = run_id(worst_row);
    limits.push_back(entry);
  }
  s["limits"] = limits;
  s["worst_position_margin_m"] = Quantiles(worst_position);
  s["worst_velocity_margin_mps"] = Quantiles(worst_velocity);
  // Which sampled parameter moves the worst margins: the columns between
  // `scenario` and the first limit, by rank correlation over the runs.
  json parameters = json::array();
  const int first_sampled = runs.Column("scenario") + 1;
  for (std::size_t c = static_cast<std::size_t>(std::max(first_sampled, 0));
       first_sampled > 0 && c < runs.header.size() && !EndsWith(runs.header[c], "_excess"); ++c) {
    std::vector<double> x, position, velocity;
    for (std::size_t r = 0; r < n; ++r) {
      const double v = runs.Number(r, static_cast<int>(c));
      if (!std::isfinite(v)) continue;
      x.push_back(v);
      position.push_back(worst_position[r]);
      velocity.push_back(worst_velocity[r]);
    }
    if (x.size() < 3) continue;
    parameters.push_back({{"parameter", runs.header[c]},
                          {"rank_correlation_position", RankCorrelation(x, position)},
                          {"rank_correlation_velocity", RankCorrelation(x, velocity)}});
  }
  s["parameters"] = parameters;

  auto column_values = [&](const char* name) {
    std::vector<double> v;
    const int c = runs.Column(name);
    if (c < 0) return v;
    for (std::size_t r = 0; r < n; ++r) {
      const double x = runs.Number(r, c);
      if (std::isfinite(x)) v.push_back(x);
    }
    return v;
  };
  auto count_positive = [&](const char* name) {
    long k = 0;
    for (const double x : column_values(name)) k += x > 0.0 ? 1 : 0;
    return k;
  };
  auto total = [&](const char* name) {
    double sum = 0.0;
    for (const double x : column_values(name)) sum += x;
    return sum;
  };
  s["tracking_rms_m"] = Quantiles(column_values("tracking_rms_m"));
  s["estimate_rms_m"] = Quantiles(column_values("estimate_rms_m"));
  s["runs_with_estimator_restarts"] = count_positive("estimator_restarts");
  s["estimator_restarts"] = total("estimator_restarts");
  s["estimator_rejections"] = total("estimator_rejections");
  s["runs_with_fallback"] = count_positive("fallback_ticks");
  s["runs_with_infeasible"] = count_positive("infeasible_ticks");
  s["runs_with_nominal_bounded"] = count_positive("nominal_bounded_ticks");
  s["runs_with_per_barrier"] = count_positive("per_barrier_ticks");
  s["runs_with_endstop_hits"] = count_positive("endstop_hits");
  s["endstop_hits"] = total("endstop_hits");
  s["runs_with_stiff_fallbacks"] = count_positive("stiff_fallbacks");
  // Runs whose supervisor never armed: their limits were the plant's with the
  // drive off, not the stack's doing (arming is refused without a usable
  // estimate or outside a limit nothing steers back from).
  if (const int armed = runs.Column("armed_s"); armed >= 0) {
    json never = json::array();
    for (std::size_t r = 0; r < n; ++r) {
      if (runs.Number(r, armed) == 0.0) never.push_back(run_id(r));
    }
    s["runs_never_armed"] = never;
  }
  // The leg-stroke barriers' band (not in "held": the limits the campaign
  // judges are the configured axis limits).
  {
    const std::vector<double> stroke = column_values("leg_stroke_margin_m");
    long beyond = 0, beyond_tolerance = 0;
    double worst = 1e9;
    for (const double m : stroke) {
      beyond += m < 0.0 ? 1 : 0;
      beyond_tolerance += -m > tolerance ? 1 : 0;
      worst = std::min(worst, m);
    }
    if (!stroke.empty() && worst < 1e8) {
      s["leg_stroke_worst_margin_m"] = worst;
      s["runs_beyond_leg_stroke_margin"] = beyond;
      s["runs_beyond_leg_stroke_margin_tolerance"] = beyond_tolerance;
    }
  }
  const std::vector<double> completed = column_values("completed");
  json failed = json::array();
  const int failure_col = runs.Column("failure");
  for (std::size_t r = 0; r < n; ++r) {
    if (runs.Number(r, runs.Column("completed")) > 0.5) continue;
    json f = run_id(r);
    if (failure_col >= 0) f["failure"] = runs.rows[r][static_cast<std::size_t>(failure_col)];
    failed.push_back(f);
  }
  s["failed_runs"] = failed;
  s["wall_s_total"] = total("wall_s");
  s["wall_s_per_run"] = Quantiles(column_values("wall_s"));
  // Any run beyond tolerance on any limit, or failed, or restarting: not held.
  long held = 0;
  for (std::size_t r = 0; r < n; ++r) {
    bool ok = runs.Number(r, runs.Column("completed")) > 0.5 &&
              runs.Number(r, runs.Column("estimator_restarts")) == 0.0;
    for (std::size_t c = 0; c < runs.header.size(); ++c) {
      if (EndsWith(runs.header[c], "_excess") && runs.Number(r, static_cast<int>(c)) > tolerance) {
        ok = false;
      }
    }
    held += ok ? 1 : 0;
  }
  s["runs_held"] = held;
  return s;
}

std::string SummaryMarkdown(const json& s) {
  std::ostringstream o;
  const json& meta = s["campaign"];
  o << "# Campaign summary\n\n";
  o << "| setting | value |\n| --- | --- |\n";
  for (auto it = meta.begin(); it != meta.end(); ++it) {
    o << "| " << it.key() << " | " << (it->is_string() ? it->get<std::string>() : it->dump())
      << " |\n";
  }
  const double tol = s["tolerance"].get<double>();
  o << "\n"
    << s["runs"].get<long>() << " runs; " << s["runs_held"].get<long>()
    << " held every limit within " << Fmt("%g", tol * 1e3)
    << " mm (mm/s), completed and without estimator restart.\n\n";
  o << "## Limits on ground truth\n\n";
  o << "| limit | runs exceeding | beyond tolerance | violation rate | worst excess | worst run "
       "(index, seed) |\n| --- | --- | --- | --- | --- | --- |\n";
  for (const json& l : s["limits"]) {
    const std::string unit = l["unit"].get<std::string>() == "m" ? "mm" : "mm/s";
    o << "| " << l["limit"].get<std::string>() << " | " << l["runs_exceeding"].get<long>() << " | "
      << l["runs_beyond_tolerance"].get<long>() << " | "
      << Fmt("%.2f %%", 100.0 * l["violation_rate"].get<double>()) << " | "
      << Fmt("%.3f", 1e3 * l["worst_excess"].get<double>()) << " " << unit << " | ";
    if (l.contains("worst_run")) {
      o << l["worst_run"]["index"].get<long>() << ", "
        << l["worst_run"]["seed"].get<unsigned long>();
    } else {
      o << "-";
    }
    o << " |\n";
  }
  auto quantile_row = [&](const char* label, const json& q, double scale, const char* unit) {
    o << "| " << label << " (" << unit << ") |";
    for (const char* k : {"min", "p01", "p05", "p50", "p95", "max"}) {
      o << " " << Fmt("%.4g", scale * q[k].get<double>()) << " |";
    }
    o << "\n";
  };
  o << "\n## Distributions over runs\n\n| quantity | min | 1 % | 5 % | median | 95 % | max |\n"
       "| --- | --- | --- | --- | --- | --- | --- |\n";
  quantile_row("worst position margin", s["worst_position_margin_m"], 1e3, "mm");
  quantile_row("worst velocity margin", s["worst_velocity_margin_mps"], 1e3, "mm/s");
  quantile_row("tracking rms, setpoints inside the limits", s["tracking_rms_m"], 1e3, "mm");
  quantile_row("estimate rms, translation", s["estimate_rms_m"], 1e3, "mm");
  quantile_row("wall time per run", s["wall_s_per_run"], 1.0, "s");
  if (s.contains("parameters") && !s["parameters"].empty()) {
    // Strongest first: the parameters that move the worst margins most.
    std::vector<json> rows(s["parameters"].begin(), s["parameters"].end());
    auto strength = [](const json& p) {
      double best = 0.0;
      for (const char* k : {"rank_correlation_position", "rank_correlation_velocity"}) {
        if (p[k].is_number()) best = std::max(best, std::fabs(p[k].get<double>()));
      }
      return best;
    };
    std::stable_sort(rows.begin(), rows.end(),
                     [&](const json& a, const json& b) { return strength(a) > strength(b); });
    o << "\n## Which parameter moves the worst margin\n\nSpearman rank correlation over the "
         "runs (+: a larger value leaves more margin; margin_vs_parameters.png shows them).\n\n"
         "| parameter | position margin | velocity margin |\n| --- | --- | --- |\n";
    constexpr std::size_t kShown = 10;
    for (std::size_t i = 0; i < rows.size() && i < kShown; ++i) {
      o << "| " << rows[i]["parameter"].get<std::string>() << " |";
      for (const char* k : {"rank_correlation_position", "rank_correlation_velocity"}) {
        o << " " << (rows[i][k].is_number() ? Fmt("%+.2f", rows[i][k].get<double>()) : "-") << " |";
      }
      o << "\n";
    }
  }
  o << "\n## Health\n\n";
  o << "- estimator restarts: " << s["estimator_restarts"].get<double>() << " in "
    << s["runs_with_estimator_restarts"].get<long>() << " runs; rejected samples "
    << s["estimator_rejections"].get<double>() << "\n";
  o << "- runs with fallback ticks: " << s["runs_with_fallback"].get<long>()
    << "; with infeasible ticks: " << s["runs_with_infeasible"].get<long>()
    << "; with the nominal bounded per period: " << s.value("runs_with_nominal_bounded", 0L)
    << "; with per-barrier answers: " << s.value("runs_with_per_barrier", 0L)
    << "; with end-stop hits: " << s["runs_with_endstop_hits"].get<long>() << " ("
    << s["endstop_hits"].get<double>()
    << " hits); plant intervals integrated by the stiff "
       "fallback in "
    << s.value("runs_with_stiff_fallbacks", 0L) << " runs\n";
  if (s.contains("leg_stroke_worst_margin_m")) {
    o << "- legs beyond the band the leg-stroke barriers keep (the stroke drawn in by its margin; "
         "not counted in held): "
      << s["runs_beyond_leg_stroke_margin"].get<long>() << " runs, "
      << s["runs_beyond_leg_stroke_margin_tolerance"].get<long>()
      << " by more than the tolerance; worst margin "
      << Fmt("%.2f", s["leg_stroke_worst_margin_m"].get<double>() * 1e3) << " mm\n";
  }
  if (s.contains("runs_never_armed")) {
    const json& never = s["runs_never_armed"];
    o << "- runs whose supervisor never armed (no usable estimate, or a start outside a limit "
         "nothing steers back from; the drive stayed off): "
      << never.size();
    constexpr std::size_t kListed = 10;
    for (std::size_t i = 0; i < never.size() && i < kListed; ++i) {
      o << (i == 0 ? " (index " : ", ") << never[i]["index"].get<long>();
    }
    if (!never.empty()) o << (never.size() > kListed ? ", ...)" : ")");
    o << "\n";
  }
  o << "- failed runs: " << s["failed_runs"].size() << "\n";
  for (const json& f : s["failed_runs"]) {
    o << "  - index " << f["index"].get<long>() << ", seed " << f["seed"].get<unsigned long>()
      << ": " << (f.contains("failure") ? f["failure"].get<std::string>() : "") << "\n";
  }
  o << "- wall time: " << Fmt("%.1f", s["wall_s_total"].get<double>())
    << " s of run time in total\n";
  return o.str();
}

}  // namespace stewart
