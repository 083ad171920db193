// stewart_log_export: an LCM log to one CSV file per channel.
//
//   stewart_log_export runs/paper/log.lcm --out runs/paper/csv
#include <spdlog/spdlog.h>

#include <CLI/CLI.hpp>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <lcm/lcm-cpp.hpp>
#include <map>
#include <memory>

#include "csv_writers.h"

int main(int argc, char** argv) {
  CLI::App app{"Export an LCM log of the stewart stack to one CSV file per channel"};
  std::string log_path, out_dir;
  app.add_option("log", log_path, "LCM log file")->required()->check(CLI::ExistingFile);
  app.add_option("-o,--out", out_dir, "output folder (default: <log>_csv)");
  CLI11_PARSE(app, argc, argv);
  if (out_dir.empty()) out_dir = log_path + "_csv";

  lcm::LogFile log(log_path, "r");
  if (!log.good()) {
    spdlog::error("cannot read LCM log '{}'", log_path);
    return 1;
  }
  std::filesystem::create_directories(out_dir);
  struct Output {
    std::ofstream file;
    const stewart::CsvChannelWriter* writer = nullptr;
    long rows = 0;
    long bad = 0;
  };
  std::map<std::string, Output> outputs;
  std::map<std::string, long> unknown;
  while (const lcm::LogEvent* event = log.readNextEvent()) {
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
      out.file.open(std::filesystem::path(out_dir) / (channel + ".csv"));
      out.file << std::setprecision(17) << "log_utime_us," << writer->Header() << '\n';
      if (!writer->SidecarName().empty()) {
        std::ofstream(std::filesystem::path(out_dir) /
                      (channel + "." + writer->SidecarName() + ".csv"))
            << writer->Sidecar(event->data, event->datalen);
      }
      it = outputs.find(channel);
    }
    Output& out = it->second;
    std::ostringstream row;
    row << std::setprecision(17);
    if (out.writer->WriteRow(event->data, event->datalen, row)) {
      out.file << event->timestamp << ',' << row.str();
      ++out.rows;
    } else {
      ++out.bad;
    }
  }
  for (const auto& [channel, out] : outputs) {
    spdlog::info("{}: {} rows{}", channel, out.rows,
                 out.bad ? fmt::format(", {} undecodable", out.bad) : "");
  }
  for (const auto& [channel, count] : unknown) {
    spdlog::warn("{}: {} messages of a type this tool does not know, skipped", channel, count);
  }
  return outputs.empty() ? 1 : 0;
}
