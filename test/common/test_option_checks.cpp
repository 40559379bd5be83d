// The validator every options loader uses: rules, their wording, and field tables read through
// Config (so Config::effective() still records each key).
#include "yolo_slam/common/config.h"
#include "yolo_slam/common/error.h"
#include "yolo_slam/common/option_checks.h"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>

using namespace yolo_slam;

namespace {

std::string messageOf(const std::function<void()>& f) {
  try {
    f();
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

enum class Colour { Red, Green };
const EnumNames<Colour> kColours = {{"red", Colour::Red}, {"green", Colour::Green}};

struct Demo {
  bool on = false;
  int count = 3;
  unsigned seed = 0;
  float share = 0.5f;
  double radius = 2.0;
};
const OptionTable<Demo> kDemoFields = {
    {"Demo.on", &Demo::on},
    {"Demo.count", &Demo::count, Range::atLeast(1)},
    {"Demo.seed", &Demo::seed, Range::atLeast(0)},
    {"Demo.share", &Demo::share, Range::fraction()},
    {"Demo.radius", &Demo::radius, Range::positive()},
};

}  // namespace

TEST(OptionChecks, RangesAndTheirWording) {
  EXPECT_EQ(Range::atLeast(1).describe(), ">= 1");
  EXPECT_EQ(Range::positive().describe(), "> 0");
  EXPECT_EQ(Range::fraction().describe(), "in (0, 1]");
  EXPECT_EQ(Range::closed(0.001, 1e6).describe(), "in [0.001, 1000000]");
  EXPECT_EQ(Range::open(0, 1).describe(), "in (0, 1)");
  EXPECT_TRUE(Range::fraction().contains(1));
  EXPECT_FALSE(Range::fraction().contains(0));
  EXPECT_FALSE(Range::open(0, 1).contains(1));
  EXPECT_FALSE(Range::any().contains(std::nan("")));
  EXPECT_FALSE(Range::atLeast(0).contains(INFINITY));
}

TEST(OptionChecks, ReadersCheckAndNameFileAndKey) {
  const Config cfg = Config::fromString("A: 0\nB: 0.25\nC: blue\n", "a.yaml");
  EXPECT_EQ(messageOf([&] { readInt(cfg, "A", 5, Range::atLeast(1)); }),
            "a.yaml: key 'A' must be >= 1 (got 0)");
  EXPECT_EQ(readFraction(cfg, "B", 1), 0.25);
  EXPECT_EQ(messageOf([&] { readPositive(cfg, "A", 1); }), "a.yaml: key 'A' must be > 0 (got 0)");
  EXPECT_EQ(readEnum(cfg, "Missing", Colour::Green, kColours), Colour::Green);
  EXPECT_EQ(messageOf([&] { readEnum(cfg, "C", Colour::Red, kColours); }),
            "a.yaml: key 'C' must be one of red, green (got 'blue')");
  EXPECT_EQ(cfg.effective()["Missing"], "green");  // defaults are recorded by name
  EXPECT_EQ(messageOf([&] { readInt(Config(), "A", 0, Range::atLeast(1)); }),
            "<config>: key 'A' must be >= 1 (got 0)");
}

TEST(OptionChecks, TablesLoadAndValidateByOneList) {
  const Config cfg = Config::fromString(
      "Demo.on: 1\nDemo.count: 4\nDemo.seed: 9\nDemo.share: 0.75\n", "demo.yaml");
  Demo d;
  readOptions(cfg, d, kDemoFields);
  EXPECT_TRUE(d.on);
  EXPECT_EQ(d.count, 4);
  EXPECT_EQ(d.seed, 9u);
  EXPECT_EQ(d.share, 0.75f);
  EXPECT_EQ(d.radius, 2.0);  // absent: the default, recorded
  EXPECT_EQ(cfg.effective()["Demo.radius"], 2.0);
  EXPECT_EQ(messageOf([&] { checkOptions(d, "Demo", kDemoFields); }), "");
  d.share = 1.5f;
  EXPECT_EQ(messageOf([&] { checkOptions(d, "Demo", kDemoFields); }),
            "Demo: key 'Demo.share' must be in (0, 1] (got 1.5)");
  Demo bad;
  EXPECT_EQ(messageOf([&] {
              readOptions(Config::fromString("Demo.seed: -2\n", "s.yaml"), bad, kDemoFields);
            }),
            "s.yaml: key 'Demo.seed' must be >= 0 (got -2)");
}
