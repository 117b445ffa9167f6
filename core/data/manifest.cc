#include "core/data/manifest.h"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>

#include <nlohmann/json.hpp>

#include "core/util/atomic_file.h"
#include "core/util/error.h"
#include "core/util/fingerprint.h"
#include "core/util/text.h"

namespace bimart {
namespace {

namespace fs = std::filesystem;
using json = nlohmann::json;

const std::vector<std::string> kSplits = {"train", "test"};

std::string type_name(const json& j) { return j.type_name(); }

std::string read_string(const json& j, const std::string& key, const std::string& where) {
  if (!j.contains(key)) return "";
  if (!j[key].is_string()) throw Error(where + ": field \"" + key + "\" must be a string, got " + type_name(j[key]));
  return j[key].get<std::string>();
}

std::vector<std::string> read_files(const json& j, const std::string& key, const std::string& where,
                                    const fs::path& folder) {
  std::vector<std::string> out;
  if (!j.contains(key)) return out;
  const json& a = j[key];
  if (!a.is_array())
    throw Error(where + ": field \"" + key + "\" must be a list of sequence files, got " + type_name(a));
  size_t missing = 0;
  std::string first_missing;
  for (size_t i = 0; i < a.size(); ++i) {
    const std::string field = "\"" + key + "\"[" + std::to_string(i) + "]";
    if (!a[i].is_string() || a[i].get<std::string>().empty())
      throw Error(where + ": field " + field + " must be a file path (a non-empty string)");
    out.push_back(a[i].get<std::string>());
    if (!fs::is_regular_file(folder / out.back()) && missing++ == 0)
      first_missing = field + " = " + (folder / out.back()).string();
  }
  if (missing > 0)
    throw Error(where + ": " + std::to_string(missing) + " listed file" + (missing > 1 ? "s do" : " does") +
                " not exist, the first: " + first_missing);
  return out;
}

}  // namespace

DatasetManifest read_manifest(const std::string& folder) {
  const fs::path file = fs::path(folder) / "manifest.json";
  const std::string where = file.string();
  if (!fs::is_directory(folder)) throw Error(folder + ": not a folder (expected a data set with a manifest.json)");
  if (!fs::exists(file)) throw Error(where + ": missing (a data set folder needs a manifest.json)");
  json j;
  try {
    std::ifstream in(file);
    if (!in) throw Error(where + ": cannot be opened");
    in >> j;
  } catch (const Error&) {
    throw;
  } catch (const std::exception& e) {
    throw Error(where + ": not valid JSON: " + e.what());
  }
  if (!j.is_object()) throw Error(where + ": must hold a JSON object, got " + type_name(j));

  DatasetManifest m;
  if (j.contains("format")) {
    const std::string format = read_string(j, "format", where);
    if (format != kManifestFormat)
      throw Error(where + ": field \"format\" is \"" + format + "\", expected \"" + kManifestFormat + "\"");
  }
  if (j.contains("version")) {
    const json& v = j["version"];
    if (!v.is_number_integer() || v.get<std::int64_t>() < 1)
      throw Error(where + ": field \"version\" must be a whole number >= 1, got " + v.dump());
    if (v.get<std::int64_t>() > kManifestVersion)
      throw Error(where + ": field \"version\" is " + v.dump() + "; this program reads manifests up to version " +
                  std::to_string(kManifestVersion) + " (written by a newer bimart?)");
    m.version = v.get<int>();
  }
  m.generator = read_string(j, "generator", where);
  if (j.contains("seed")) {
    const json& s = j["seed"];
    if (!s.is_number_unsigned() && !(s.is_number_integer() && s.get<std::int64_t>() >= 0))
      throw Error(where + ": field \"seed\" must be a whole number >= 0, got " + s.dump());
    m.seed = s.get<std::uint64_t>();
  }
  if (j.contains("fps")) {
    const json& f = j["fps"];
    if (!f.is_number() || !std::isfinite(f.get<double>()) || !(f.get<double>() > 0))
      throw Error(where + ": field \"fps\" must be a positive number, got " + f.dump());
    m.fps = f.get<double>();
  }
  m.train = read_files(j, "train", where, folder);
  m.test = read_files(j, "test", where, folder);
  if (!j.contains("train") && !j.contains("test"))
    throw Error(where + ": lists no sequences (fields \"train\" and \"test\" are both missing)");

  std::map<std::string, std::string> seen;  // normalised path -> split
  for (const std::string& split : kSplits)
    for (const std::string& f : split == "train" ? m.train : m.test) {
      const std::string key = (fs::path(folder) / f).lexically_normal().string();
      auto [it, fresh] = seen.emplace(key, split);
      if (!fresh)
        throw Error(where + ": " + f + " is listed " +
                    (it->second == split ? "twice in \"" + split + "\"" : "in both \"train\" and \"test\""));
    }

  if (j.contains("objects")) {
    const json& a = j["objects"];
    if (!a.is_array()) throw Error(where + ": field \"objects\" must be a list, got " + type_name(a));
    for (size_t i = 0; i < a.size(); ++i) {
      const std::string field = "\"objects\"[" + std::to_string(i) + "]";
      if (!a[i].is_object())
        throw Error(where + ": field " + field + " must be an object {name, path, category, split}");
      const std::string w = where + ": field " + field;
      DatasetObject o;
      o.name = read_string(a[i], "name", w);
      o.path = read_string(a[i], "path", w);
      o.category = read_string(a[i], "category", w);
      o.split = read_string(a[i], "split", w);
      if (o.path.empty()) throw Error(w + " has no \"path\"");
      if (!fs::exists(fs::path(folder) / o.path))
        throw Error(w + ": object " + (fs::path(folder) / o.path).string() + " does not exist");
      m.objects.push_back(std::move(o));
    }
  }
  return m;
}

void write_manifest(const DatasetManifest& m, const std::string& folder) {
  const fs::path file = fs::path(folder) / "manifest.json";
  if (m.version < 1 || m.version > kManifestVersion)
    throw Error(file.string() + ": cannot write manifest version " + std::to_string(m.version) +
                " (this program writes version " + std::to_string(kManifestVersion) + ")");
  if (!std::isfinite(m.fps) || !(m.fps > 0))
    throw Error(file.string() + ": fps must be a positive number, got " + std::to_string(m.fps));
  json j;
  j["format"] = kManifestFormat;
  j["version"] = m.version;
  j["generator"] = m.generator;
  j["seed"] = m.seed;
  j["fps"] = m.fps;
  j["train"] = m.train;
  j["test"] = m.test;
  json objects = json::array();
  for (const DatasetObject& o : m.objects)
    objects.push_back({{"name", o.name}, {"path", o.path}, {"category", o.category}, {"split", o.split}});
  j["objects"] = std::move(objects);
  // nlohmann keeps keys sorted; the order above is only for the reader of this code.
  write_file_atomically(file.string(), [&](std::ostream& out) { out << j.dump(2) << "\n"; });
}

std::vector<std::string> split_files(const DatasetManifest& m, const std::string& folder, const std::string& split) {
  const std::vector<std::string>* list = split == "train" ? &m.train : split == "test" ? &m.test : nullptr;
  if (!list)
    throw Error("unknown data split '" + split + "'" + did_you_mean(split, kSplits) +
                " (known: " + join(kSplits, ", ") + ")");
  std::vector<std::string> out;
  out.reserve(list->size());
  for (const std::string& f : *list) out.push_back((fs::path(folder) / f).lexically_normal().string());
  return out;
}

std::string dataset_fingerprint(const std::string& folder) {
  const DatasetManifest m = read_manifest(folder);
  std::ifstream in(fs::path(folder) / "manifest.json", std::ios::binary);
  const std::string manifest_text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  Fnv f;
  f.add(manifest_text);
  for (const auto* split : {&m.train, &m.test})
    for (const auto& name : *split) {
      std::error_code ec;
      f.add(name);
      f.add_value(static_cast<std::uint64_t>(fs::file_size(fs::path(folder) / name, ec)));
    }
  return f.hex();
}

}  // namespace bimart
