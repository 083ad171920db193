#pragma once
// What a campaign's runs.csv says, in numbers (summary.json) and words
// (summary.md): violation rate and worst excess per limit with the run that
// caused it, quantiles of the worst margin, tracking and estimator health.
// Computed from the CSV alone, so merged shards summarise as one campaign.
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace stewart {

struct CsvTable {
  std::vector<std::string> header;
  std::vector<std::vector<std::string>> rows;
  /// Index of a column; -1 when absent.
  int Column(const std::string& name) const;
  double Number(std::size_t row, int column) const;
};

/// One CSV field: quoted (RFC 4180) when it holds a comma, a quote or a line
/// break; a line break becomes a space so a row stays one line.
std::string CsvField(const std::string& s);

/// Reads a CSV written by the campaign (RFC 4180 quoting). Throws InputError
/// naming the file and line when a row has the wrong number of fields.
CsvTable ReadCsv(const std::string& path);
/// The same from text; `source` names it in errors.
CsvTable ParseCsv(const std::string& text, const std::string& source);
void WriteCsv(const std::string& path, const CsvTable& table);

/// `meta` (campaign settings) is copied into the summary's "campaign" entry.
nlohmann::json SummarizeCampaign(const CsvTable& runs, const nlohmann::json& meta,
                                 double tolerance);
std::string SummaryMarkdown(const nlohmann::json& summary);

}  // namespace stewart
