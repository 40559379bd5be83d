#pragma once
// The one way options are read and checked. Loaders read each key with its default and its rule
// in one call; validate() of options built in code applies the same rules. Every rejection
// throws yolo_slam::Error "<file>: key '<Key>' must be <rule> (got <value>)".
//
// A struct lists its fields once (OptionTable: key, member, rule); readOptions() loads them from
// a Config and checkOptions() checks a struct set in code, so both follow one table.
#include <limits>
#include <string>
#include <utility>
#include <variant>
#include <vector>

namespace yolo_slam {

class Config;

// Allowed values: an interval with open or closed ends, either end may be infinite. NaN and
// infinities are never allowed.
struct Range {
  static constexpr double kInf = std::numeric_limits<double>::infinity();
  double lo = -kInf;
  double hi = kInf;
  bool lo_open = false, hi_open = false;

  static Range any() { return {}; }
  static Range atLeast(double lo) { return {lo, kInf, false, false}; }
  static Range positive() { return {0, kInf, true, false}; }
  static Range fraction() { return {0, 1, true, false}; }  // (0, 1]
  static Range closed(double lo, double hi) { return {lo, hi, false, false}; }
  static Range open(double lo, double hi) { return {lo, hi, true, true}; }
  static Range openClosed(double lo, double hi) { return {lo, hi, true, false}; }

  bool contains(double v) const;
  // The rule as the messages print it: ">= 1", "> 0", "in (0, 1]", "finite".
  std::string describe() const;
};

// The name messages give a Config: its path, or "<config>" when it has none.
std::string configName(const Config& cfg);
// "%.15g": 0.2 prints as 0.2, 5.0 as 5.
std::string formatNumber(double v);

// Throws yolo_slam::Error "<where>: key '<key>' must be <rule> (got <got>)".
[[noreturn]] void rejectOption(const std::string& where, const std::string& key,
                               const std::string& rule, const std::string& got);
void checkOption(const std::string& where, const std::string& key, double v, const Range& r);

// Read `key` (def when absent) and check it against the rule; `where` of a rejection is the
// Config's name.
int readInt(const Config& cfg, const std::string& key, int def, const Range& r);
double readDouble(const Config& cfg, const std::string& key, double def, const Range& r);
double readPositive(const Config& cfg, const std::string& key, double def);  // > 0
double readFraction(const Config& cfg, const std::string& key, double def);  // in (0, 1]

// The accepted names of an enum, in the order messages list them.
template <class E>
using EnumNames = std::vector<std::pair<std::string, E>>;

// "a, b, c" of the names.
template <class E>
std::string listNames(const EnumNames<E>& names) {
  std::string out;
  for (const auto& n : names) out += (out.empty() ? "" : ", ") + n.first;
  return out;
}

// The value named `s`, or null.
template <class E>
const E* findEnum(const EnumNames<E>& names, const std::string& s) {
  for (const auto& n : names)
    if (n.first == s) return &n.second;
  return nullptr;
}

// The name of `v` ("?" if it has none).
template <class E>
std::string nameOf(const EnumNames<E>& names, E v) {
  for (const auto& n : names)
    if (n.second == v) return n.first;
  return "?";
}

std::string readEnumName(const Config& cfg, const std::string& key, const std::string& def);

template <class E>
E readEnum(const Config& cfg, const std::string& key, E def, const EnumNames<E>& names) {
  const std::string s = readEnumName(cfg, key, nameOf(names, def));
  if (const E* v = findEnum(names, s)) return *v;
  rejectOption(configName(cfg), key, "one of " + listNames(names), "'" + s + "'");
}

// ---- Field tables -------------------------------------------------------------------------

template <class S>
struct OptionField {
  using Member = std::variant<bool S::*, int S::*, unsigned S::*, float S::*, double S::*>;
  const char* key;
  Member member;
  Range rule = Range::any();  // ignored for bool fields
};
template <class S>
using OptionTable = std::vector<OptionField<S>>;

namespace option_detail {
void read(const Config& cfg, const char* key, bool& v, const Range& r);
void read(const Config& cfg, const char* key, int& v, const Range& r);
void read(const Config& cfg, const char* key, unsigned& v, const Range& r);
void read(const Config& cfg, const char* key, float& v, const Range& r);
void read(const Config& cfg, const char* key, double& v, const Range& r);
inline void check(const std::string&, const char*, bool, const Range&) {}
template <class T>
void check(const std::string& where, const char* key, T v, const Range& r) {
  checkOption(where, key, static_cast<double>(v), r);
}
}  // namespace option_detail

// Reads every field of `table` into `s`; the values already in `s` are the defaults.
template <class S>
void readOptions(const Config& cfg, S& s, const OptionTable<S>& table) {
  for (const auto& f : table)
    std::visit([&](auto m) { option_detail::read(cfg, f.key, s.*m, f.rule); }, f.member);
}

// Checks every field of `table` in `s`; `where` names the struct in messages.
template <class S>
void checkOptions(const S& s, const std::string& where, const OptionTable<S>& table) {
  for (const auto& f : table)
    std::visit([&](auto m) { option_detail::check(where, f.key, s.*m, f.rule); }, f.member);
}

}  // namespace yolo_slam
