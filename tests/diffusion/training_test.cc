// Training on the tiny data set: the config file, an interrupted run resumes to the
// identical loss curve and weights, and two processes on loopback train exactly like one
// process on the union of their batches.
#include <gtest/gtest.h>

#include <torch/optim/adam.h>

#include <ATen/ATen.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <cstdlib>
#include <initializer_list>
#include <thread>

#include "core/data/normalization.h"
#include "core/diffusion/checkpoint.h"
#include "core/diffusion/distributed.h"
#include "core/diffusion/generation.h"
#include "core/diffusion/schedule.h"
#include "core/diffusion/training.h"
#include "core/util/error.h"
#include "tests/data/tiny_dataset.h"
#include "tests/diffusion/tiny_train_config.h"
#include "tests/diffusion/union_of_batches.h"
#include "tests/error_of.h"

namespace bimart::diffusion {
namespace {

namespace fs = std::filesystem;

fs::path scratch(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / ("bimart_train_" + std::to_string(::getpid())) / name;
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

TrainConfig tiny_config(const fs::path& out, const std::string& model = "motion") {
  TrainConfig c = tiny_train_config(out, model);
  c.network.dropout = 0.1;
  c.steps = 6;
  c.lr = 1e-3;
  c.warmup = 2;
  c.validate_every = 3;
  c.validation_windows = 4;
  c.log_every = 1;
  c.seed = 11;
  return c;
}

std::vector<std::string> lines(const fs::path& file) {
  std::ifstream in(file);
  std::vector<std::string> v;
  for (std::string l; std::getline(in, l);) v.push_back(l);
  return v;
}

// The loss columns (step, lr, loss, validation) of loss.csv; time and rate differ per run.
std::vector<std::string> loss_columns(const fs::path& file) {
  std::vector<std::string> out;
  for (const auto& l : lines(file)) {
    std::size_t pos = 0;
    for (int i = 0; i < 4 && pos != std::string::npos; ++i) pos = l.find(',', pos + 1);
    out.push_back(l.substr(0, pos));
  }
  return out;
}

TEST(Training, ConfigFileErrorsNameTheLine) {
  const fs::path dir = scratch("config");
  const fs::path good = dir / "good.yaml";
  std::ofstream(good) << "model: contact\ndata: d\nout: o\nnetwork:\n  latent: 64\n  heads: 4\ntraining:\n  steps: 7\n";
  const TrainConfig c = load_train_config(good.string());
  EXPECT_EQ(c.model, "contact");
  EXPECT_EQ(c.network.latent, 64);
  EXPECT_EQ(c.network.sample_size, 2048);
  EXPECT_EQ(c.network.contact_condition_size, 0);
  EXPECT_EQ(c.steps, 7);
  EXPECT_NE(c.text.find("latent: 64"), std::string::npos);
  const fs::path bad = dir / "bad.yaml";
  std::ofstream(bad) << "model: motion\ndata: d\nout: o\ntraining:\n  stepz: 7\n";
  try {
    load_train_config(bad.string());
    FAIL() << "accepted an unknown key";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("bad.yaml:5"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("stepz"), std::string::npos) << e.what();
  }
  std::ofstream(bad) << "model: motion\ndata: d\nout: o\nnetwork:\n  heads: 7\n";
  EXPECT_THROW(load_train_config(bad.string()), Error);  // 7 does not divide 512
  // Contact maps in log space: the contact model's, read from the network section.
  std::ofstream(good) << "model: contact\ndata: d\nout: o\nnetwork:\n  contact_log_eps: 0.005\n";
  EXPECT_DOUBLE_EQ(load_train_config(good.string()).contact_log_eps, 0.005);
  std::ofstream(bad) << "model: motion\ndata: d\nout: o\nnetwork:\n  contact_log_eps: 0.005\n";
  EXPECT_THROW(load_train_config(bad.string()), Error);
  std::ofstream(bad) << "model: contact\ndata: d\nout: o\nnetwork:\n  contact_log_eps: -1\n";
  EXPECT_THROW(load_train_config(bad.string()), Error);
  // The contact basis: 2K numbers per frame; the contact model's only, at most 1024.
  std::ofstream(good) << "model: contact\ndata: d\nout: o\nnetwork:\n  contact_basis: 64\n";
  EXPECT_EQ(load_train_config(good.string()).network.sample_size, 128);
  std::ofstream(bad) << "model: motion\ndata: d\nout: o\nnetwork:\n  contact_basis: 64\n";
  EXPECT_THROW(load_train_config(bad.string()), Error);
  std::ofstream(bad) << "model: contact\ndata: d\nout: o\nnetwork:\n  contact_basis: 1025\n";
  EXPECT_THROW(load_train_config(bad.string()), Error);
  // The schedule's shift, in (0, 1].
  std::ofstream(good) << "model: motion\ndata: d\nout: o\ndiffusion:\n  shift: 0.25\n";
  EXPECT_DOUBLE_EQ(load_train_config(good.string()).schedule_shift, 0.25);
  std::ofstream(bad) << "model: motion\ndata: d\nout: o\ndiffusion:\n  shift: 2\n";
  EXPECT_THROW(load_train_config(bad.string()), Error);
}

TEST(Training, ContactModelInABasisSamplesFullMapsFromItsSubspace) {
  const fs::path dir = scratch("basis");
  TrainConfig c = tiny_config(dir, "contact");
  c.contact_basis = 4;
  c.schedule_shift = 0.5;  // stored with the model, used by its sampler
  TrainOptions quiet;
  quiet.progress = false;
  EXPECT_THROW(train(c, quiet), Error);  // sample size still 2048
  c.network.sample_size = 8;
  EXPECT_TRUE(train(c, quiet).finished);
  const Checkpoint ck = load_checkpoint((dir / "checkpoint.npz").string());
  const NormalizationStats& st = ck.info.normalization;
  ASSERT_TRUE(st.c_basis.defined());
  ASSERT_EQ(st.c_basis.sizes(), (at::IntArrayRef{1024, 4}));
  // Sampled maps are full [S, N, 2, 1024] maps in metres, from the 4-direction subspace
  // (up to the clamp at 0): projecting and reconstructing them changes nothing.
  const DiffusionModel model(ck, (dir / "checkpoint.npz").string());
  EXPECT_DOUBLE_EQ(ck.info.schedule_shift, 0.5);
  EXPECT_EQ(model.schedule().alphas_cumprod, make_schedule("squaredcos_cap_v2", 50, 0.5).alphas_cumprod);
  GenerateOptions o;
  o.sampler.sampler = "ddim";
  o.sampler.steps = 3;
  o.samples = 2;
  const at::Tensor O = at::randn({10, 1024, 3}) * 0.1, G = at::zeros({10, 7});
  const at::Tensor C = model.generate(O, G, {}, nullptr, o, at::detail::createCPUGenerator(3));
  ASSERT_EQ(C.sizes(), (at::IntArrayRef{2, 10, 2, 1024}));
  EXPECT_GE(C.min().item<double>(), 0.0);
  const at::Tensor positive = C > 0;
  const at::Tensor again = st.contact_from_sample(st.contact_sample(C));
  EXPECT_LT((again - C).masked_select(positive).abs().max().item<double>(), 0.05 * C.abs().max().item<double>());
  // A checkpoint whose network does not match its statistics' basis is refused.
  Checkpoint broken = ck;
  broken.info.normalization.c_basis = at::Tensor();
  EXPECT_THROW(DiffusionModel(broken, "broken.npz"), Error);
}

TEST(Training, WarmStartFromAModelWithoutTheContactCueKeepsItsOutput) {
  // The cue adds input columns to the contact MLP; they start at zero, so the warm-started
  // model computes what the old one did, whatever the cue says.
  DenoiserConfig old_config = tiny_config("/unused").network;
  old_config.dropout = 0;
  DenoiserConfig new_config = old_config;
  new_config.contact_cue = true;
  torch::manual_seed(5);
  Denoiser old_net(old_config), new_net(new_config);
  EXPECT_EQ(warm_start(*new_net, state_of(*old_net)), static_cast<int>(new_net->named_parameters().size()));
  torch::NoGradGuard ng;
  new_net->set_cue_frame(at::zeros({3079}), at::ones({3079}), at::zeros({2048}), at::ones({2048}),
                         at::randn({1024, 3}), true);
  at::Tensor obj = at::randn({2, 4, 3079});
  obj.select(2, 3078).fill_(2.0);
  const at::Tensor C = at::rand({2, 4, 2048}), x = at::randn({2, 4, 1200}), t = at::tensor({3, 40});
  EXPECT_TRUE(at::allclose(new_net->encode_conditions(obj, C), old_net->encode_conditions(obj, C), 1e-5, 1e-6));
  EXPECT_TRUE(at::allclose(new_net->forward(x, t, new_net->encode_conditions(obj, C)),
                           old_net->forward(x, t, old_net->encode_conditions(obj, C)), 1e-4, 1e-5));
  // A parameter of another shape is left as it was.
  DenoiserConfig wider = old_config;
  wider.condition_hidden = 24;
  Denoiser other(wider);
  EXPECT_LT(warm_start(*other, state_of(*old_net)), static_cast<int>(other->named_parameters().size()));
}

TEST(Training, NoisyShareDrawsThatShareOfStepsFromTheNoisiestOnes) {
  TrainConfig c = tiny_config(scratch("noisy"));
  c.batch = 20;
  WindowDatasetOptions wo;
  const WindowDataset data = WindowDataset::open(c.data, "train", wo);
  const NormalizationStats stats = compute_normalization(data);
  const auto share_from = [&](int from) {
    double n = 0;
    for (int step = 0; step < 20; ++step) n += (draw_step(c, stats, data, step, 0).t >= from).sum().item<double>();
    return n / (20.0 * c.batch);
  };
  const at::Tensor uniform = draw_step(c, stats, data, 0, 0).t;
  EXPECT_NEAR(share_from(40), 10.0 / 50.0, 0.07);  // uniform: 10 of 50 steps (400 draws: σ 0.02)
  c.noisy_share = 0.5;
  c.noisy_from = 40;
  // Half from [40, 50), half uniform: P(t >= 40) = 0.5 + 0.5 · 0.2.
  EXPECT_NEAR(share_from(40), 0.6, 0.07);
  c.noisy_share = 1.0;  // all from [40, 50)
  const at::Tensor noisy = draw_step(c, stats, data, 0, 0).t;
  EXPECT_GE(noisy.min().item<std::int64_t>(), 40);
  EXPECT_LE(noisy.max().item<std::int64_t>(), 49);
  // The uniform draw is unchanged by the option's existence.
  c.noisy_share = 0;
  EXPECT_TRUE(at::equal(draw_step(c, stats, data, 0, 0).t, uniform));
  c.noisy_from = 50;
  EXPECT_THROW(validate(c), Error);
}

TEST(Training, LearningRateWarmsUpThenDecays) {
  TrainConfig c;
  c.lr = 1e-3;
  c.warmup = 10;
  c.steps = 110;
  EXPECT_NEAR(learning_rate(c, 0), 1e-4, 1e-15);
  EXPECT_NEAR(learning_rate(c, 9), 1e-3, 1e-15);
  EXPECT_NEAR(learning_rate(c, 10), 1e-3, 1e-15);
  EXPECT_NEAR(learning_rate(c, 60), 0.5e-3, 1e-12);
  EXPECT_NEAR(learning_rate(c, 110), 0.0, 1e-15);
}

TEST(Training, ResumedRunEqualsAnUninterruptedOne) {
  const fs::path a = scratch("whole"), b = scratch("parts");
  TrainOptions quiet;
  quiet.progress = false;
  TensorMap wa, wb;
  TrainOptions oa = quiet;
  oa.final_weights = &wa;
  const TrainResult ra = train(tiny_config(a), oa);
  EXPECT_TRUE(ra.finished);
  EXPECT_EQ(ra.steps_done, 6);

  TrainOptions first = quiet;
  first.stop_after = 4;  // not on a checkpoint boundary: the stop writes one
  const TrainResult r1 = train(tiny_config(b), first);
  EXPECT_FALSE(r1.finished);
  EXPECT_EQ(r1.steps_done, 4);
  TrainOptions rest = quiet;
  rest.resume = true;
  rest.final_weights = &wb;
  const TrainResult r2 = train(tiny_config(b), rest);
  EXPECT_TRUE(r2.finished);
  EXPECT_EQ(r2.steps_done, 6);

  const auto la = loss_columns(a / "loss.csv"), lb = loss_columns(b / "loss.csv");
  ASSERT_EQ(la.size(), 7u);  // header + 6 steps
  EXPECT_EQ(la, lb);
  ASSERT_EQ(wa.size(), wb.size());
  for (const auto& [k, v] : wa) EXPECT_TRUE(at::equal(v, wb.at(k))) << k;
  const Checkpoint ca = load_checkpoint((a / "checkpoint.npz").string());
  const Checkpoint cb = load_checkpoint((b / "checkpoint.npz").string());
  for (const auto& [k, v] : ca.weights) EXPECT_TRUE(at::equal(v, cb.weights.at(k))) << "EMA " << k;
  ASSERT_TRUE(ca.train.has_value());
  EXPECT_EQ(ca.train->step, 6);
  EXPECT_EQ(ca.info.keypoints.size(), 100u);
  EXPECT_EQ(ca.info.basis_points.sizes(), (std::vector<int64_t>{1024, 3}));
}

TEST(Training, HalfExportHoldsTheRoundedEmaWeightsAndAFinishedRunRewritesIt) {
  const fs::path dir = scratch("half");
  TrainConfig c = tiny_config(dir);
  c.steps = 3;
  c.export_path = (dir / "model.npz").string();
  c.export_half = true;
  TrainOptions quiet;
  quiet.progress = false;
  train(c, quiet);
  const Checkpoint full = load_checkpoint((dir / "checkpoint.npz").string());
  const auto check_export = [&]() {
    const Checkpoint half = load_checkpoint(c.export_path);
    EXPECT_FALSE(half.train.has_value());
    const Denoiser net = make_denoiser(half, c.export_path);
    int n = 0;
    for (const auto& p : net->named_parameters()) {
      EXPECT_TRUE(at::equal(p.value(), full.weights.at(p.key()).to(at::kHalf).to(at::kFloat))) << p.key();
      ++n;
    }
    EXPECT_GT(n, 10);
  };
  check_export();
  fs::remove(c.export_path);
  TrainOptions again = quiet;
  again.resume = true;
  EXPECT_EQ(train(c, again).steps_done, 3);  // nothing left to train ...
  ASSERT_TRUE(fs::exists(c.export_path));     // ... but the missing export is written again
  check_export();
}

TEST(Training, ResumeRefusesAnotherNetwork) {
  const fs::path dir = scratch("other_net");
  TrainOptions o;
  o.progress = false;
  TrainConfig c = tiny_config(dir);
  c.steps = 2;
  train(c, o);
  c.network.latent = 32;
  o.resume = true;
  EXPECT_THROW(train(c, o), Error);
}

// What the network learns is set by the schedule and the contact basis too: a resume that
// changes either is refused, with the two settings in the message.
TEST(Training, ResumeRefusesAnotherScheduleShiftOrContactBasis) {
  const fs::path dir = scratch("other_schedule");
  TrainOptions o;
  o.progress = false;
  TrainConfig c = tiny_config(dir, "contact");
  c.steps = 2;
  c.contact_basis = 4;
  c.network.sample_size = 8;
  train(c, o);
  o.resume = true;
  TrainConfig shifted = c;
  shifted.schedule_shift = 0.5;
  const std::string shift_error = test::error_of([&] { train(shifted, o); });
  EXPECT_NE(shift_error.find("shift 1 vs squaredcos_cap_v2, 50 steps, shift 0.5"), std::string::npos) << shift_error;
  TrainConfig wider = c;
  wider.contact_basis = 6;
  wider.network.sample_size = 12;
  const std::string basis_error = test::error_of([&] { train(wider, o); });
  EXPECT_NE(basis_error.find("contact basis differs"), std::string::npos) << basis_error;
  EXPECT_NE(basis_error.find("sample size 8 vs 12"), std::string::npos) << basis_error;
  c.steps = 3;
  EXPECT_TRUE(train(c, o).finished);  // the same settings resume
}

TEST(Training, TwoProcessesEqualOneOnTheUnionOfTheirBatches) {
  const fs::path dir = scratch("parallel");
  TrainConfig c = tiny_config(dir, "motion");
  c.network.dropout = 0.0;  // dropout masks depend on the batch layout
  c.grad_clip = 0.0;
  c.batch = 2;
  c.steps = 3;
  c.validate_every = 0;
  const int port = 20000 + static_cast<int>(::getpid() % 20000);
  TensorMap w[2];
  std::string errors[2];
  std::vector<std::thread> ranks;
  for (int r = 0; r < 2; ++r) {
    ranks.emplace_back([&, r] {
      try {
        DataParallelOptions d;
        d.world_size = 2;
        d.rank = r;
        d.master_port = port;
        d.timeout_seconds = 60;
        TrainOptions o;
        o.progress = false;
        o.parallel = std::make_shared<DataParallel>(d);
        o.final_weights = &w[r];
        train(c, o);
      } catch (const std::exception& e) {
        errors[r] = e.what();
      }
    });
  }
  for (auto& t : ranks) t.join();
  ASSERT_EQ(errors[0], "");
  ASSERT_EQ(errors[1], "");
  for (const auto& [k, v] : w[0]) EXPECT_TRUE(at::equal(v, w[1].at(k))) << "ranks differ in " << k;

  // One process, the union of both ranks' batches, the same steps.
  const TensorMap reference = train_on_union_of_batches(c, 2);
  const double worst = largest_parameter_difference(reference, w[0]);
  EXPECT_LE(worst, 1e-5);
}

}  // namespace
}  // namespace bimart::diffusion

namespace bimart::diffusion {
namespace {

// Sets (or, with nullptr, unsets) environment variables for one scope.
class ScopedEnv {
 public:
  ScopedEnv(std::initializer_list<std::pair<const char*, const char*>> vars) {
    for (const auto& [k, v] : vars) {
      const char* old = std::getenv(k);
      saved_.push_back({k, old != nullptr, old != nullptr ? old : ""});
      if (v != nullptr) ::setenv(k, v, 1);
      else ::unsetenv(k);
    }
  }
  ~ScopedEnv() {
    for (auto it = saved_.rbegin(); it != saved_.rend(); ++it) {
      if (it->had) ::setenv(it->name.c_str(), it->value.c_str(), 1);
      else ::unsetenv(it->name.c_str());
    }
  }

 private:
  struct Saved {
    std::string name;
    bool had;
    std::string value;
  };
  std::vector<Saved> saved_;
};

TEST(Distributed, FirstHostOfASlurmNodeList) {
  EXPECT_EQ(first_slurm_host("node7"), "node7");
  EXPECT_EQ(first_slurm_host("gpu[03-05,9],cpu1"), "gpu03");
  EXPECT_EQ(first_slurm_host("cn[7,2-4]"), "cn7");
  EXPECT_EQ(first_slurm_host("a-[1-2]-x,b"), "a-1-x");
  EXPECT_EQ(first_slurm_host("r[2-3]n[01-04]"), "r2n01");
  EXPECT_THROW(first_slurm_host(""), Error);
  EXPECT_THROW(first_slurm_host("n[]"), Error);
}

TEST(Distributed, SlurmVariablesStandInForUnsetTorchOnesInsideASrunStep) {
  {
    ScopedEnv env{{"WORLD_SIZE", nullptr},           {"RANK", nullptr},          {"MASTER_ADDR", nullptr},
                  {"MASTER_PORT", nullptr},          {"SLURM_STEP_NUM_TASKS", "4"}, {"SLURM_PROCID", "2"},
                  {"SLURM_STEP_NODELIST", "n[12-13]"}, {"SLURM_JOB_ID", "12345"}};
    const auto o = DataParallel::options_from_environment();
    ASSERT_TRUE(o.has_value());
    EXPECT_EQ(o->world_size, 4);
    EXPECT_EQ(o->rank, 2);
    EXPECT_EQ(o->master_addr, "n12");
    EXPECT_EQ(o->master_port, 15000 + 12345 % 20000);
    {
      ScopedEnv torch_wins{{"MASTER_PORT", "29999"}, {"MASTER_ADDR", "10.0.0.1"}};
      const auto t = DataParallel::options_from_environment();
      ASSERT_TRUE(t.has_value());
      EXPECT_EQ(t->master_port, 29999);
      EXPECT_EQ(t->master_addr, "10.0.0.1");
    }
    {
      ScopedEnv bad{{"SLURM_PROCID", "x"}};
      const std::string e = test::error_of([] { DataParallel::options_from_environment(); });
      EXPECT_NE(e.find("SLURM_PROCID"), std::string::npos) << e;
    }
  }
  {
    // A batch script outside any srun step, or a step of one task: one process.
    ScopedEnv env{{"WORLD_SIZE", nullptr}, {"SLURM_STEP_NUM_TASKS", nullptr}, {"SLURM_NTASKS", "4"},
                  {"SLURM_PROCID", "0"}};
    EXPECT_FALSE(DataParallel::options_from_environment().has_value());
    ScopedEnv one{{"SLURM_STEP_NUM_TASKS", "1"}};
    EXPECT_FALSE(DataParallel::options_from_environment().has_value());
  }
  {
    ScopedEnv env{{"WORLD_SIZE", "2"}, {"RANK", "1"}, {"MASTER_ADDR", "h"}, {"MASTER_PORT", "1234"},
                  {"SLURM_STEP_NUM_TASKS", nullptr}};
    const auto o = DataParallel::options_from_environment();
    ASSERT_TRUE(o.has_value());
    EXPECT_EQ(o->rank, 1);
    EXPECT_EQ(o->master_addr, "h");
  }
}

}  // namespace
}  // namespace bimart::diffusion
