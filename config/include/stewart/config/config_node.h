#pragma once
// Typed, path-aware access to the YAML configuration. Every failure throws a
// ConfigError whose message names the full key ("safety.k_position") and the
// reason, so a bad config gives one clear line.
#include <yaml-cpp/yaml.h>

#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "stewart/common/check.h"
#include "stewart/common/enum_table.h"
#include "stewart/model/types.h"

namespace stewart {

/// Bad configuration: the InputError of a YAML file, naming the full key.
class ConfigError : public InputError {
 public:
  ConfigError(const std::string& key, const std::string& reason);
};

class ConfigNode {
 public:
  ConfigNode(YAML::Node node, std::string path);

  const std::string& path() const { return path_; }
  std::string KeyPath(std::string_view key) const;
  bool Has(std::string_view key) const;

  /// A required mapping.
  ConfigNode Child(std::string_view key) const;
  /// A required sequence of mappings.
  std::vector<ConfigNode> List(std::string_view key) const;

  double Double(std::string_view key) const;  ///< finite
  double PositiveDouble(std::string_view key) const;
  double NonNegativeDouble(std::string_view key) const;
  std::optional<double> OptionalDouble(std::string_view key) const;
  int Int(std::string_view key) const;
  /// An integer within [lo, hi]; outside, the error says `reason`.
  int IntInRange(std::string_view key, int lo, int hi, const std::string& reason) const;
  bool Bool(std::string_view key) const;
  std::string String(std::string_view key) const;
  /// A string that must be one of `allowed`.
  std::string Choice(std::string_view key, const std::vector<std::string>& allowed) const;
  /// A string that must be one of the table's names: its value.
  template <typename Enum, std::size_t N>
  Enum EnumValue(std::string_view key, const EnumTable<Enum, N>& table) const {
    return *table.Find(Choice(key, table.NameList()));
  }
  Vector3d Vec3(std::string_view key) const;
  Vector6d Vec6(std::string_view key) const;
  std::array<double, 6> Array6(std::string_view key) const;

  [[noreturn]] void Fail(std::string_view key, const std::string& reason) const;

 private:
  YAML::Node Required(std::string_view key) const;
  template <int N>
  Eigen::Matrix<double, N, 1> FixedVector(std::string_view key) const;

  YAML::Node node_;
  std::string path_;
};

}  // namespace stewart
