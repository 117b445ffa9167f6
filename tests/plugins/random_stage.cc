// test.random: writes `count` numbers from the stage's seeded generator to a text file.
#include <fstream>
#include <random>

#include "core/pipeline/plugin.h"
#include "core/util/atomic_file.h"
#include "stages/exporter.h"

namespace {
class RandomNumbers : public bimart::Exporter {
 public:
  static bimart::StageSpec spec() {
    return bimart::StageSpec::of<bimart::Exporter>("random_numbers", "writes seeded random numbers")
        .param("count", 8, "how many")
        .param("path", "out/random.txt", "file to write");
  }
  explicit RandomNumbers(const bimart::Params& p) : count_(p.integer("count")), path_(p.string("path")) {}
  void run(bimart::StageIO& io) override {
    std::uniform_int_distribution<long long> d(0, 1000000000);
    bimart::write_file_atomically(path_, [&](std::ostream& out) {
      for (long long i = 0; i < count_; ++i) out << d(io.rng()) << "\n";
    });
    io.out("path", path_);
  }

 private:
  long long count_;
  std::string path_;
};
}  // namespace

BIMART_REGISTER_STAGE(RandomNumbers)
