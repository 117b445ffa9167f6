// Small string helpers shared by the CLI and error messages.
#pragma once

#include <string>
#include <vector>

namespace bimart {

// Edit distance (insert, delete, substitute, each cost 1).
int edit_distance(const std::string& a, const std::string& b);

// The candidates closest to `wanted` (at most `max_results`, only reasonably close ones),
// best first; for "did you mean" hints.
std::vector<std::string> closest_names(const std::string& wanted,
                                       const std::vector<std::string>& candidates,
                                       std::size_t max_results = 3);

// " (did you mean 'a' or 'b'?)" or "" when nothing is close.
std::string did_you_mean(const std::string& wanted, const std::vector<std::string>& candidates);

// True for [a-z_][a-z0-9_]* (stage ids) or, with allow_leading_underscore false,
// [a-z][a-z0-9_]* (kinds and names in stage keys).
bool is_lower_identifier(const std::string& s, bool allow_leading_underscore = true);

// "1h05m", "4m10s", "12s"; "?" for a negative or non-finite time.
std::string format_duration(double seconds);

std::string join(const std::vector<std::string>& parts, const std::string& sep);

// Demangled C++ name of a type_info (falls back to the mangled name).
std::string demangle(const char* mangled);

}  // namespace bimart
