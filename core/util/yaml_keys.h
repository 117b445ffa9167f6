// Duplicate keys in YAML. yaml-cpp accepts them silently (a block map keeps the first
// value, a flow map the last), so a second `frames:` would be ignored or win by accident.
// This walks the parser's events and refuses them, naming both lines. Also: unknown keys of
// a map, and a node's place in its file.
#pragma once

#include <string>
#include <vector>

#include "core/util/error.h"

namespace YAML {
class Node;
}

namespace bimart {

// The node's 1-based line and column in `file` (0 when yaml-cpp does not know them).
SourceLocation yaml_location(const std::string& file, const YAML::Node& node);

// Throws bimart::Error "file:L:C: unknown key 'k' in WHAT (did you mean ...?; known: a, b)"
// for the first key of the map `node` that is not in `known`. A non-map is left alone.
void check_known_keys(const YAML::Node& node, const std::vector<std::string>& known, const std::string& file,
                      const std::string& what);

// Throws bimart::Error "file:L2:C2: key 'k' is given twice (first at line L1)". Syntax
// errors are left to the caller's own YAML::Load (nothing is thrown for them here).
void check_duplicate_keys(const std::string& text, const std::string& file);

}  // namespace bimart
