#include "stewart/config/config_node.h"

#include <cmath>
#include <sstream>

namespace stewart {

ConfigError::ConfigError(const std::string& key, const std::string& reason)
    : InputError(key, reason, "config error at '" + key + "': " + reason) {}

ConfigNode::ConfigNode(YAML::Node node, std::string path)
    : node_(std::move(node)), path_(std::move(path)) {}

std::string ConfigNode::KeyPath(std::string_view key) const {
  return path_.empty() ? std::string(key) : path_ + "." + std::string(key);
}

void ConfigNode::Fail(std::string_view key, const std::string& reason) const {
  throw ConfigError(KeyPath(key), reason);
}

bool ConfigNode::Has(std::string_view key) const {
  return node_.IsMap() && node_[std::string(key)].IsDefined() && !node_[std::string(key)].IsNull();
}

YAML::Node ConfigNode::Required(std::string_view key) const {
  if (!node_.IsMap()) throw ConfigError(path_.empty() ? "<root>" : path_, "expected a mapping");
  const YAML::Node child = node_[std::string(key)];
  if (!child.IsDefined() || child.IsNull()) Fail(key, "missing required key");
  return child;
}

ConfigNode ConfigNode::Child(std::string_view key) const {
  const YAML::Node child = Required(key);
  if (!child.IsMap()) Fail(key, "expected a mapping");
  return ConfigNode(child, KeyPath(key));
}

std::vector<ConfigNode> ConfigNode::List(std::string_view key) const {
  const YAML::Node child = Required(key);
  if (!child.IsSequence()) Fail(key, "expected a list");
  std::vector<ConfigNode> out;
  for (std::size_t i = 0; i < child.size(); ++i) {
    out.emplace_back(child[i], KeyPath(key) + "[" + std::to_string(i) + "]");
    if (!child[i].IsMap()) throw ConfigError(out.back().path(), "expected a mapping");
  }
  return out;
}

namespace {
double ScalarToDouble(const ConfigNode& parent, std::string_view key, const YAML::Node& node) {
  if (!node.IsScalar()) parent.Fail(key, "expected a number");
  double value = 0.0;
  if (!YAML::convert<double>::decode(node, value)) {
    parent.Fail(key, "expected a number, got '" + node.Scalar() + "'");
  }
  if (!std::isfinite(value)) parent.Fail(key, "must be finite, got '" + node.Scalar() + "'");
  return value;
}
}  // namespace

double ConfigNode::Double(std::string_view key) const {
  return ScalarToDouble(*this, key, Required(key));
}

double ConfigNode::PositiveDouble(std::string_view key) const {
  const double v = Double(key);
  if (!(v > 0.0)) Fail(key, "must be positive, got " + std::to_string(v));
  return v;
}

double ConfigNode::NonNegativeDouble(std::string_view key) const {
  const double v = Double(key);
  if (v < 0.0) Fail(key, "must not be negative, got " + std::to_string(v));
  return v;
}

std::optional<double> ConfigNode::OptionalDouble(std::string_view key) const {
  if (!Has(key)) return std::nullopt;
  return Double(key);
}

int ConfigNode::Int(std::string_view key) const {
  const YAML::Node node = Required(key);
  int value = 0;
  if (!node.IsScalar() || !YAML::convert<int>::decode(node, value)) {
    Fail(key, "expected an integer, got '" + (node.IsScalar() ? node.Scalar() : "?") + "'");
  }
  return value;
}

int ConfigNode::IntInRange(std::string_view key, int lo, int hi, const std::string& reason) const {
  const int value = Int(key);
  if (value < lo || value > hi) Fail(key, reason);
  return value;
}

bool ConfigNode::Bool(std::string_view key) const {
  const YAML::Node node = Required(key);
  bool value = false;
  if (!node.IsScalar() || !YAML::convert<bool>::decode(node, value)) {
    Fail(key, "expected true or false");
  }
  return value;
}

std::string ConfigNode::String(std::string_view key) const {
  const YAML::Node node = Required(key);
  if (!node.IsScalar()) Fail(key, "expected a string");
  return node.Scalar();
}

std::string ConfigNode::Choice(std::string_view key,
                               const std::vector<std::string>& allowed) const {
  const std::string value = String(key);
  for (const auto& a : allowed) {
    if (a == value) return value;
  }
  std::ostringstream msg;
  msg << "'" << value << "' is not one of:";
  for (const auto& a : allowed) msg << " " << a;
  Fail(key, msg.str());
}

template <int N>
Eigen::Matrix<double, N, 1> ConfigNode::FixedVector(std::string_view key) const {
  const YAML::Node node = Required(key);
  if (!node.IsSequence() || node.size() != static_cast<std::size_t>(N)) {
    Fail(key, "expected a list of " + std::to_string(N) + " numbers");
  }
  Eigen::Matrix<double, N, 1> v;
  for (int i = 0; i < N; ++i) {
    const std::string element = std::string(key) + "[" + std::to_string(i) + "]";
    v(i) = ScalarToDouble(*this, element, node[static_cast<std::size_t>(i)]);
  }
  return v;
}

Vector3d ConfigNode::Vec3(std::string_view key) const { return FixedVector<3>(key); }
Vector6d ConfigNode::Vec6(std::string_view key) const { return FixedVector<6>(key); }

std::array<double, 6> ConfigNode::Array6(std::string_view key) const {
  const Vector6d v = Vec6(key);
  return {v(0), v(1), v(2), v(3), v(4), v(5)};
}

}  // namespace stewart
