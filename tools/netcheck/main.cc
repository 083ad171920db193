// stewart_netcheck: can this host hear the others on the stack's bus?
// tools/launch.sh --check-network runs one on every host at once
// (docs/operations.md, "Several hosts").
//
//   stewart_netcheck --lcm-url URL --id NAME [--duration-s 2]
//
// Sends a probe every 50 ms on STEWART_NETCHECK (a short LCM datagram whose
// payload is "NAME seq"), listens for the same time, and prints one line per
// host heard, "heard NAME COUNT", after "sent COUNT". A socket that cannot
// join the group (no multicast route) is one clear error and exit 1.
#include <CLI/CLI.hpp>
#include <chrono>
#include <cstdio>
#include <exception>
#include <map>
#include <string>
#include <thread>
#include <vector>

#include "stewart/node/lcm_receiver.h"
#include "stewart/node/raw_bus_sender.h"

int main(int argc, char** argv) {
  using namespace stewart;
  CLI::App app{"can this host hear the others on the stack's bus", "stewart_netcheck"};
  std::string url, id;
  double duration_s = 2.0;
  app.add_option("--lcm-url", url, "the stack's URL")->required();
  app.add_option("--id", id, "this host's name in the probes")->required();
  app.add_option("--duration-s", duration_s, "how long to send and listen")
      ->check(CLI::Range(0.1, 60.0));
  CLI11_PARSE(app, argc, argv);
  constexpr const char* kChannel = "STEWART_NETCHECK";
  try {
    LcmReceiver receiver(url);
    RawBusSender bus(url);
    std::map<std::string, int> heard;
    receiver.SubscribeAll([&](const lcm::ReceiveBuffer& rbuf, const std::string& channel) {
      if (channel != kChannel) return;
      const std::string payload(static_cast<const char*>(rbuf.data), rbuf.data_size);
      const std::string who = payload.substr(0, payload.find(' '));
      if (!who.empty() && who.size() < 64) ++heard[who];
    });
    const auto start = std::chrono::steady_clock::now();
    const auto end = start + std::chrono::duration<double>(duration_s);
    int sent = 0;
    auto next = start;
    while (std::chrono::steady_clock::now() < end) {
      if (std::chrono::steady_clock::now() >= next) {
        const std::string payload = id + " " + std::to_string(sent);
        if (bus.Send(LcmShortDatagram(static_cast<uint32_t>(sent), kChannel,
                                      std::vector<uint8_t>(payload.begin(), payload.end())))) {
          ++sent;
        }
        next += std::chrono::milliseconds(50);
      }
      receiver.HandleTimeout(10);
    }
    // The others' last probes may still be in flight.
    const auto linger = std::chrono::steady_clock::now() + std::chrono::milliseconds(200);
    while (std::chrono::steady_clock::now() < linger) receiver.HandleTimeout(10);
    std::printf("sent %d\n", sent);
    for (const auto& [who, count] : heard) std::printf("heard %s %d\n", who.c_str(), count);
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "stewart_netcheck: %s\n", e.what());
    return 1;
  }
}
