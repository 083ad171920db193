#pragma once
#include <lcm/lcm-cpp.hpp>
#include <memory>
#include <string>

namespace stewart {

/// Creates an LCM instance on `url` and checks good(). Throws
/// std::runtime_error with the likely cause (no multicast route) otherwise.
std::unique_ptr<lcm::LCM> MakeLcm(const std::string& url);

/// A private URL for tests and launches: udpm on 239.255.76.67:<port>, ttl=0
/// so nothing leaves this machine.
std::string PrivateLcmUrl(int port);

}  // namespace stewart
