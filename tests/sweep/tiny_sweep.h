// A tiny sweep for the sweep tests (sweep_test.cc, slurm_test.cc): tiny models trained on
// the tiny data set, a pipeline of contact maps, motion and the MANO fit, and three rows
// of which two share their run.
#pragma once

#include <sys/wait.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "tests/cli/run_bimart.h"
#include "tests/data/tiny_dataset.h"

namespace bimart::test {

namespace tiny_fs = std::filesystem;

// An empty folder of this test process under the temporary folder: PREFIX + pid.
inline tiny_fs::path fresh_scratch_folder(const std::string& prefix) {
  const tiny_fs::path p = tiny_fs::temp_directory_path() / (prefix + std::to_string(::getpid()));
  tiny_fs::remove_all(p);
  tiny_fs::create_directories(p);
  return p;
}

inline std::string read_text(const tiny_fs::path& p) {
  std::ifstream in(p);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

inline void write_text(const tiny_fs::path& p, const std::string& text) {
  tiny_fs::create_directories(p.parent_path());
  std::ofstream(p) << text;
}

inline std::string tiny_sweep_config(const std::string& model, int steps, int checkpoint_every = 2) {
  return "model: " + model + "\ndata: " + testing_data::tiny_dataset().dir.string() +
         "\nout: unused\nvariant: np_bps\nstride: 16\n"
         "network: {latent: 16, layers: 1, heads: 2, feedforward: 32, condition_hidden: 32, dropout: 0.1}\n"
         "diffusion: {schedule: squaredcos_cap_v2, steps: 10}\n"
         "training: {batch: 4, steps: " +
         std::to_string(steps) + ", lr: 1.0e-3, warmup: 2, noisy_from: 5, seed: 1, checkpoint_every: " +
         std::to_string(checkpoint_every) + ", validate_every: 0, log_every: 5}\n";
}

// contact maps, motion, MANO fit, one export: the rows' runs.
inline const char* tiny_sweep_pipeline() {
  return R"(name: tiny_eval
stages:
  - id: sequence
    use: trajectory.sequence
    params: {path: unused.npz}
  - id: encoder
    use: encoder.np_bps
  - id: contact
    use: contact.diffusion
  - id: motion
    use: motion.diffusion
  - id: fit
    use: refine.mano_fit
  - id: guided
    use: export.sequence
    params: {path: unused.npz}
)";
}

// The sweep file over the inputs in `dir` (write_tiny_sweep_inputs): rows "w C", "w/o C"
// and "NP-BPS" (the same run as "w C"), then `extra_rows`; models "contact" and "motion",
// then `extra_models` (YAML lines indented by two spaces).
inline std::string tiny_sweep_text(const tiny_fs::path& dir, const std::string& without_c_extra = "",
                                   const std::string& extra_models = "", const std::string& extra_rows = "") {
  return "name: tiny\n"
         "base:\n"
         "  data: " + testing_data::tiny_dataset().dir.string() + "\n"
         "  split: test\n  samples: 2\n  seed: 0\n  window: 32\n"
         "  pipeline: " + (dir / "tiny_eval.yaml").string() + "\n"
         "  output: guided\n"
         "models:\n"
         "  contact: {train: " + (dir / "contact.yaml").string() + "}\n"
         "  motion: {train: " + (dir / "motion.yaml").string() + "}\n" +
         extra_models +
         "rows:\n"
         "  - name: w C\n"
         "    section: Contact\n"
         "    models: {contact: contact, motion: motion}\n"
         "    paper: {Mul: 6.97928, Accel: 0.31398, Pen 1cm: 20.273, Con: 98.481, Art: 83.089, CM: 1.1505}\n"
         "  - name: w/o C\n"
         "    section: Contact\n"
         "    models: {contact: contact, motion: motion}\n"
         "    set: {motion.use_contact: false" + without_c_extra + "}\n"
         "    paper: {Mul: 4.4894, Accel: 0.31034, Pen 1cm: 9.4481, Con: 96.129, Art: 79.591}\n"
         "  - name: NP-BPS\n"
         "    section: Rep\n"
         "    models: {contact: contact, motion: motion}\n" +
         extra_rows;
}

// The training configs and the pipeline the sweep file names.
inline void write_tiny_sweep_inputs(const tiny_fs::path& dir, int steps, int checkpoint_every = 2) {
  write_text(dir / "contact.yaml", tiny_sweep_config("contact", steps, checkpoint_every));
  write_text(dir / "motion.yaml", tiny_sweep_config("motion", steps, checkpoint_every));
  write_text(dir / "tiny_eval.yaml", tiny_sweep_pipeline());
}

// The table's CSV without its wall-time column.
inline std::string table_numbers(const tiny_fs::path& dir) {
  std::string out;
  std::istringstream in(read_text(dir / "table.csv"));
  for (std::string line; std::getline(in, line);) out += line.substr(0, line.rfind(',')) + "\n";
  return out;
}

}  // namespace bimart::test
