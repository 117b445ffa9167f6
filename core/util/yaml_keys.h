// Duplicate keys in YAML. yaml-cpp accepts them silently (a block map keeps the first
// value, a flow map the last), so a second `frames:` would be ignored or win by accident.
// This walks the parser's events and refuses them, naming both lines.
#pragma once

#include <string>

namespace bimart {

// Throws bimart::Error "file:L2:C2: key 'k' is given twice (first at line L1)". Syntax
// errors are left to the caller's own YAML::Load (nothing is thrown for them here).
void check_duplicate_keys(const std::string& text, const std::string& file);

}  // namespace bimart
