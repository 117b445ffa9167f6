// bimart bps make: writes a BPS basis file. The shipped files in models/bps/ were made with
// it; a model is trained with one basis and must always be given that same file.
#include <iostream>

#include <filesystem>

#include "core/cli/command.h"
#include "core/cli/common_options.h"
#include "core/features/bps.h"
#include "core/util/error.h"
#include "core/util/output_path.h"

namespace bimart::cli {

void add_bps_commands(CLI::App& app, Commands& out) {
  CLI::App* bps = app.add_subcommand("bps", "basis point sets for the object encoders");
  bps->require_subcommand(1);
  static std::string variant = "np_bps", path;
  static std::uint64_t seed = 0;
  static bool force = false;
  CLI::App* make = bps->add_subcommand("make", "write a basis file (points uniform in a ball, from a seed)");
  make->add_option("--variant", variant, "encoder the basis is for: np_bps (512 in the unit ball), "
                                         "npa_bps (1024 in the unit ball) or u_bps (1024 in a 0.5 m ball)")
      ->check(CLI::IsMember({"np_bps", "npa_bps", "u_bps"}));
  add_seed_option(make, seed, "random seed (default 0)");
  make->add_flag("--force", force, "replace an existing file (the shipped basis included)");
  make->add_option("--out", path, "output .npz (default: the variant's shipped file under models/bps/)");
  out.push_back({make,
                 [] {
                   const BpsVariant v = variant == "u_bps"     ? BpsVariant::Uniform
                                        : variant == "npa_bps" ? BpsVariant::PartAgnostic
                                                               : BpsVariant::PerPart;
                   const std::string file = path.empty() ? default_basis_file(v) : path;
                   // A model is trained with one basis: replacing it silently breaks every model.
                   if (std::filesystem::exists(file) && !force)
                     throw Error(file + " exists (a model trained with it needs exactly this basis); "
                                 "give --out NEW.npz, or --force to replace it");
                   check_output_file(file);
                   save_bps_basis(make_bps_basis(basis_size(v), v == BpsVariant::Uniform ? 0.5 : 1.0, seed), file);
                   std::cout << "wrote " << file << "\n";
                   return 0;
                 },
                 false});
}

}  // namespace bimart::cli
