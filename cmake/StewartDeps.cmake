# Dependencies found the way Debian 12 ships them.
find_package(Eigen3 3.4 REQUIRED NO_MODULE)
find_package(yaml-cpp REQUIRED)
find_package(spdlog REQUIRED)
find_package(CLI11 CONFIG REQUIRED)
find_package(nlohmann_json 3 REQUIRED)
find_package(GTest REQUIRED)
find_package(benchmark REQUIRED)
find_package(Threads REQUIRED)
# HMAC-SHA256 of the authenticated channels (node/message_auth.h).
find_package(OpenSSL 3 REQUIRED COMPONENTS Crypto)

# LCM 1.3.1 ships no CMake package and its lcm.pc drags in glib headers:
# link the library directly and run lcm-gen ourselves (see lcmtypes/).
find_library(LCM_LIBRARY NAMES lcm REQUIRED)
find_path(LCM_INCLUDE_DIR NAMES lcm/lcm-cpp.hpp REQUIRED)
find_program(LCM_GEN lcm-gen REQUIRED)
add_library(lcm::lcm UNKNOWN IMPORTED)
set_target_properties(lcm::lcm PROPERTIES IMPORTED_LOCATION ${LCM_LIBRARY}
                      INTERFACE_INCLUDE_DIRECTORIES ${LCM_INCLUDE_DIR})
find_file(LCM_JAR lcm.jar PATHS /usr/share/java NO_DEFAULT_PATH)
find_package(Java COMPONENTS Development)
