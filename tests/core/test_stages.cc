#include "test_stages.h"

#include <random>

namespace bimart::test {
namespace {

template <class T>
StageEntry entry() {
  return {T::spec(), [](const Params& p) -> std::unique_ptr<Stage> { return std::make_unique<T>(p); },
          "<test>"};
}

struct Source : Stage {
  static StageSpec spec() {
    return StageSpec("test.source", "a number")
        .param("value", 1.0, "the number")
        .param("count", 3, "unused")
        .yaml_param("extra", "unused; YAML text")
        .output<double>("value", "the number");
  }
  explicit Source(const Params& p) : v(p.number("value")) {}
  void run(StageIO& io) override { io.out("value", v); }
  double v;
};

struct Double : Stage {
  static StageSpec spec() {
    return StageSpec("test.double", "x2").input<double>("value", "in").output<double>("value", "out");
  }
  explicit Double(const Params&) {}
  void run(StageIO& io) override { io.out("value", 2 * io.in<double>("value")); }
};

struct Sink : Stage {
  static StageSpec spec() {
    return StageSpec("test.sink", "formats")
        .input<double>("value", "in")
        .optional_input<std::string>("extra", "appended")
        .output<std::string>("result", "text");
  }
  explicit Sink(const Params&) {}
  void run(StageIO& io) override {
    std::string s = std::to_string(io.in<double>("value"));
    if (io.has("extra")) s += io.in<std::string>("extra");
    io.out("result", s);
  }
};

struct Text : Stage {
  static StageSpec spec() { return StageSpec("test.text", "text").output<std::string>("value", "text"); }
  explicit Text(const Params&) {}
  void run(StageIO& io) override { io.out("value", std::string("hello")); }
};

struct Random : Stage {
  static StageSpec spec() {
    return StageSpec("test.random", "draws").param("count", 4, "how many").output<std::vector<std::int64_t>>("draws", "numbers");
  }
  explicit Random(const Params& p) : n(p.integer("count")) {}
  void run(StageIO& io) override {
    std::vector<std::int64_t> d;
    for (std::int64_t i = 0; i < n; ++i) d.push_back(static_cast<std::int64_t>(io.rng()() >> 1));
    io.out("draws", d);
  }
  std::int64_t n;
};

struct Lazy : Stage {
  static StageSpec spec() { return StageSpec("test.lazy", "forgets").output<double>("value", "never"); }
  explicit Lazy(const Params&) {}
  void run(StageIO&) override {}
};

struct Strict : Stage {
  static StageSpec spec() {
    return StageSpec("test.strict", "checks").param("positive", 1.0, "> 0").output<double>("value", "v");
  }
  explicit Strict(const Params& p) {
    if (p.number("positive") <= 0) throw Error("positive must be > 0");
  }
  void run(StageIO& io) override { io.out("value", 1.0); }
};

struct CycleA : Stage {
  static StageSpec spec() { return StageSpec("test.cycle_a", "a").input<double>("a", "").output<double>("b", ""); }
  explicit CycleA(const Params&) {}
  void run(StageIO& io) override { io.out("b", io.in<double>("a")); }
};

struct CycleB : Stage {
  static StageSpec spec() { return StageSpec("test.cycle_b", "b").input<double>("b", "").output<double>("a", ""); }
  explicit CycleB(const Params&) {}
  void run(StageIO& io) override { io.out("a", io.in<double>("b")); }
};

}  // namespace

Registry make_registry() {
  Registry r;
  r.add({entry<Source>(), entry<Double>(), entry<Sink>(), entry<Text>(), entry<Random>(), entry<Lazy>(),
         entry<Strict>(), entry<CycleA>(), entry<CycleB>()});
  return r;
}

}  // namespace bimart::test
