// "Did you mean" for a mistyped command, option or joint name: the known names nearest to what
// was typed, by edit distance (insertions, deletions, substitutions and swaps of neighbours).
#pragma once
#include <string>
#include <vector>

#include "keyanim/skeleton.h"

namespace keyanim::cli {

// The candidates within a distance of about a third of what was typed (at least 1, at most 3),
// nearest first, at most `most`; ties keep the candidates' order. Case is ignored.
std::vector<std::string> nearest_names(const std::string& typed, const std::vector<std::string>& candidates,
                                       size_t most = 3);

// " (did you mean 'X'?)", " (did you mean 'X', 'Y' or 'Z'?)", or "" when nothing is near.
std::string did_you_mean(const std::string& typed, const std::vector<std::string>& candidates, size_t most = 1);

// "no joint named 'LeftHnd' (did you mean 'LeftHand'?; `keyanim info FILE` lists the joints)":
// up to three near joint names (End Sites are not joints).
std::string no_joint_message(const Skeleton& skeleton, const std::string& typed);

}  // namespace keyanim::cli
