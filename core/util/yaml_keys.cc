#include "core/util/yaml_keys.h"

#include <yaml-cpp/eventhandler.h>
#include <yaml-cpp/exceptions.h>
#include <yaml-cpp/parser.h>
#include <yaml-cpp/yaml.h>

#include <map>
#include <utility>
#include <sstream>
#include <vector>

#include "core/util/error.h"
#include "core/util/text.h"

namespace bimart {
namespace {

class DuplicateKeys : public YAML::EventHandler {
 public:
  explicit DuplicateKeys(std::string file) : file_(std::move(file)) {}

  void OnDocumentStart(const YAML::Mark&) override {}
  void OnDocumentEnd() override {}
  void OnNull(const YAML::Mark& m, YAML::anchor_t) override { node(m, nullptr); }
  void OnAlias(const YAML::Mark& m, YAML::anchor_t) override { node(m, nullptr); }
  void OnScalar(const YAML::Mark& m, const std::string&, YAML::anchor_t, const std::string& value) override {
    node(m, &value);
  }
  void OnSequenceStart(const YAML::Mark&, const std::string&, YAML::anchor_t, YAML::EmitterStyle::value) override {
    open(false);
  }
  void OnSequenceEnd() override { close(); }
  void OnMapStart(const YAML::Mark&, const std::string&, YAML::anchor_t, YAML::EmitterStyle::value) override {
    open(true);
  }
  void OnMapEnd() override { close(); }

 private:
  struct Level {
    bool map;
    bool expect_key = true;
    std::map<std::string, YAML::Mark> keys;
  };

  void open(bool map) {
    // A container used as a key or a value counts as one node of its parent when it closes.
    Level level;
    level.map = map;
    stack_.push_back(std::move(level));
  }
  void close() {
    stack_.pop_back();
    advance();
  }
  void advance() {
    if (!stack_.empty() && stack_.back().map) stack_.back().expect_key = !stack_.back().expect_key;
  }
  void node(const YAML::Mark& m, const std::string* scalar) {
    if (!stack_.empty() && stack_.back().map && stack_.back().expect_key && scalar) {
      auto [it, fresh] = stack_.back().keys.emplace(*scalar, m);
      if (!fresh)
        throw Error(SourceLocation{file_, m.line + 1, m.column + 1},
                    "key '" + *scalar + "' is given twice (first at line " + std::to_string(it->second.line + 1) +
                        "); remove one");
    }
    advance();
  }

  std::string file_;
  std::vector<Level> stack_;
};

}  // namespace

void check_duplicate_keys(const std::string& text, const std::string& file) {
  std::istringstream in(text);
  DuplicateKeys handler(file);
  try {
    // The first document only, as YAML::Load reads. (Looping over HandleNextDocument
    // never ended on some inputs, e.g. ",ame:" — found by fuzzing.)
    YAML::Parser parser(in);
    parser.HandleNextDocument(handler);
  } catch (const YAML::Exception&) {
    // Syntax errors: the caller's YAML::Load reports them with their own position.
  }
}

SourceLocation yaml_location(const std::string& file, const YAML::Node& node) {
  const YAML::Mark m = node.Mark();
  return {file, m.line >= 0 ? m.line + 1 : 0, m.column >= 0 ? m.column + 1 : 0};
}

void check_known_keys(const YAML::Node& node, const std::vector<std::string>& known, const std::string& file,
                      const std::string& what) {
  if (!node.IsMap()) return;
  for (const auto& kv : node) {
    const std::string key = kv.first.Scalar();
    bool found = false;
    for (const std::string& k : known) found = found || k == key;
    if (!found)
      throw Error(yaml_location(file, kv.first),
                  "unknown key '" + key + "' in " + what + did_you_mean(key, known) + " (known: " + join(known, ", ") + ")");
  }
}

}  // namespace bimart
