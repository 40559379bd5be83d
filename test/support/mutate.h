#pragma once
// Seeded random mutation of valid inputs for the bounded fuzz tests (no libFuzzer needed):
// bit flips, random bytes, truncation, inserted and deleted runs, duplicated chunks. The number
// of mutants per target is YS_FUZZ_ITERATIONS (scripts/sanitize.sh runs many more).
#include <algorithm>
#include <cstdlib>
#include <random>
#include <string>

namespace test_support {

inline int fuzzIterations(int def) {
  const char* env = std::getenv("YS_FUZZ_ITERATIONS");
  if (!env || !*env) return def;
  const int n = std::atoi(env);
  return n > 0 ? n : def;
}

class Mutator {
 public:
  explicit Mutator(unsigned seed) : rng_(seed) {}

  // `valid` with one to four random edits.
  std::string mutate(const std::string& valid) {
    std::string s = valid;
    const int edits = 1 + static_cast<int>(below(4));
    for (int k = 0; k < edits; ++k) edit(s);
    return s;
  }
  size_t below(size_t n) { return n == 0 ? 0 : std::uniform_int_distribution<size_t>(0, n - 1)(rng_); }

 private:
  char randomByte() {
    // Bytes that matter to text parsers come up more often than uniform chance gives them.
    static const char kInteresting[] = {'\0', '\n', ' ', ':', '-', '.', 'e', '9', '[', '"', '#', '\xff'};
    if (below(3) == 0) return kInteresting[below(sizeof kInteresting)];
    return static_cast<char>(below(256));
  }
  void edit(std::string& s) {
    const size_t at = below(s.size() + 1);
    switch (below(6)) {
      case 0:  // bit flip
        if (!s.empty()) s[at % s.size()] ^= static_cast<char>(1u << below(8));
        break;
      case 1:  // byte replaced
        if (!s.empty()) s[at % s.size()] = randomByte();
        break;
      case 2:  // truncation
        s.resize(at);
        break;
      case 3:  // inserted bytes
        for (size_t n = 1 + below(8); n > 0; --n) s.insert(s.begin() + static_cast<long>(std::min(at, s.size())), randomByte());
        break;
      case 4:  // deleted run
        s.erase(std::min(at, s.size()), 1 + below(16));
        break;
      default:  // a chunk repeated elsewhere
        if (!s.empty()) {
          const size_t from = below(s.size());
          s.insert(std::min(at, s.size()), s.substr(from, 1 + below(32)));
        }
    }
  }
  std::mt19937 rng_;
};

}  // namespace test_support
