// stewart_log_export: an LCM log to one CSV file per channel, and how
// complete the log is (the seq numbers of its streams).
//
//   stewart_log_export runs/paper/log.lcm --out runs/paper/csv [--continuity-json FILE]
//   stewart_log_export runs/paper/log.lcm --check [--continuity-json FILE]
#include <spdlog/spdlog.h>

#include <CLI/CLI.hpp>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <lcm/lcm-cpp.hpp>
#include <map>
#include <memory>

#include "continuity_report.h"
#include "csv_writers.h"
#include "stewart/common/seq_continuity.h"

int main(int argc, char** argv) {
  CLI::App app{"Export an LCM log of the stewart stack to one CSV file per channel"};
  std::string log_path, out_dir, continuity_json;
  bool check_only = false;
  app.add_option("log", log_path, "LCM log file")->required()->check(CLI::ExistingFile);
  app.add_option("-o,--out", out_dir, "output folder (default: <log>_csv)");
  app.add_flag("--check", check_only,
               "write no CSV: only say how complete the log is (messages missing per stream, "
               "publisher restarts)");
  app.add_option("--continuity-json", continuity_json,
                 "write the log's completeness per stream, with its gaps and restarts, to FILE");
  CLI11_PARSE(app, argc, argv);
  if (out_dir.empty()) out_dir = log_path + "_csv";

  lcm::LogFile log(log_path, "r");
  if (!log.good()) {
    spdlog::error("cannot read LCM log '{}'", log_path);
    return 1;
  }
  if (!check_only) std::filesystem::create_directories(out_dir);
  struct Output {
    std::ofstream file;
    const stewart::CsvChannelWriter* writer = nullptr;
    long rows = 0;
    long bad = 0;
  };
  std::map<std::string, Output> outputs;
  std::map<std::string, long> unknown;
  stewart::SeqContinuity continuity;
  stewart::LogSpan span;
  long position = 0;
  for (; const lcm::LogEvent* event = log.readNextEvent(); ++position) {
    if (position == 0) span.first_log_utime = event->timestamp;
    span.last_log_utime = event->timestamp;
    const std::string channel = event->channel;
    auto it = outputs.find(channel);
    if (it == outputs.end()) {
      const stewart::CsvChannelWriter* writer = stewart::FindCsvWriter(event->data, event->datalen);
      if (writer == nullptr) {
        ++unknown[channel];
        continue;
      }
      Output& out = outputs[channel];
      out.writer = writer;
      if (!check_only) {
        out.file.open(std::filesystem::path(out_dir) / (channel + ".csv"));
        out.file << std::setprecision(17) << "log_utime_us," << writer->Header() << '\n';
        if (!writer->SidecarName().empty()) {
          std::ofstream(std::filesystem::path(out_dir) /
                        (channel + "." + writer->SidecarName() + ".csv"))
              << writer->Sidecar(event->data, event->datalen);
        }
      }
      it = outputs.find(channel);
    }
    Output& out = it->second;
    if (const auto stamp = out.writer->Stamp(event->data, event->datalen)) {
      const std::string stream =
          stamp->publisher.empty() ? channel : channel + "[" + stamp->publisher + "]";
      continuity.Observe(stream, stamp->seq, stamp->utime, event->timestamp, position);
    }
    if (check_only) {
      ++out.rows;
      continue;
    }
    std::ostringstream row;
    row << std::setprecision(17);
    if (out.writer->WriteRow(event->data, event->datalen, row)) {
      out.file << event->timestamp << ',' << row.str();
      ++out.rows;
    } else {
      ++out.bad;
    }
  }
  if (!check_only) {
    for (const auto& [channel, out] : outputs) {
      spdlog::info("{}: {} rows{}", channel, out.rows,
                   out.bad ? fmt::format(", {} undecodable", out.bad) : "");
    }
  }
  for (const auto& [channel, count] : unknown) {
    spdlog::warn("{}: {} messages of a type this tool does not know, skipped", channel, count);
  }
  std::cout << stewart::FormatContinuity(continuity, span) << std::flush;
  if (!continuity_json.empty()) {
    std::ofstream json(continuity_json);
    json << stewart::ContinuityJson(continuity, span).dump(1) << '\n';
    if (!json) {
      spdlog::error("cannot write '{}'", continuity_json);
      return 1;
    }
  }
  return outputs.empty() ? 1 : 0;
}
