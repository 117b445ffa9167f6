// A data set folder's manifest, FOLDER/manifest.json (docs/data_loader.md): who wrote the
// set, its seed and frame rate, the sequence files of the train and test splits and the
// objects they use. Synthetic sets (`bimart data synth`) and converted ARCTIC sets write the
// same file, so the training data loader (core/data/window_dataset.h) and
// `bimart eval --split` read both alike.
//
//   {"format": "bimart-dataset", "version": 1, "generator": "bimart data synth 0.1.0",
//    "seed": 7, "fps": 30, "train": ["sequences/a.npz", ...], "test": [...],
//    "objects": [{"name": "laptop_3", "path": "objects/laptop_3", "category": "laptop",
//                 "split": "train"}, ...]}
//
// Paths are relative to the folder. Reading accepts a hand-written minimal manifest
// (only "train" and/or "test"); every known key that is present is checked, other keys
// are ignored (converters may add their own).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace bimart {

constexpr const char* kManifestFormat = "bimart-dataset";
constexpr int kManifestVersion = 1;  // the newest version this program reads and writes

struct DatasetObject {
  std::string name, path, category, split;  // path relative to the folder
};

struct DatasetManifest {
  int version = 1;
  std::string generator;  // e.g. "bimart data synth 0.1.0" or "arctic_to_sequences.py"
  std::uint64_t seed = 0;
  double fps = 30;
  std::vector<std::string> train, test;  // sequence files relative to the folder
  std::vector<DatasetObject> objects;
};

// Reads FOLDER/manifest.json. Throws bimart::Error naming the file and the field on a
// missing file, invalid JSON, a wrong "format", a newer "version", a field of the wrong
// type, a listed sequence or object that does not exist, or a file in both splits.
DatasetManifest read_manifest(const std::string& folder);

// Writes FOLDER/manifest.json atomically (the folder is created when missing). Throws
// bimart::Error for a version this program does not know or a non-positive fps.
void write_manifest(const DatasetManifest& m, const std::string& folder);

// The files of `split` ("train" or "test") joined to `folder`, in manifest order. An
// unknown split throws bimart::Error listing the known ones.
std::vector<std::string> split_files(const DatasetManifest& m, const std::string& folder, const std::string& split);

// The data set's fingerprint (stored in checkpoints, part of sweep job keys): its manifest's
// text and every listed file's name (relative to the folder) and size. Independent of how
// the folder's path is spelled.
std::string dataset_fingerprint(const std::string& folder);

}  // namespace bimart
