#include "suggest.h"

#include <algorithm>
#include <cctype>
#include <utility>

namespace keyanim::cli {
namespace {

std::string lower(const std::string& s) {
  std::string out = s;
  for (char& ch : out) ch = static_cast<char>(std::tolower(static_cast<unsigned char>(ch)));
  return out;
}

// Optimal string alignment distance (Damerau-Levenshtein without repeated edits of a substring).
size_t distance(const std::string& a, const std::string& b) {
  std::vector<std::vector<size_t>> d(a.size() + 1, std::vector<size_t>(b.size() + 1));
  for (size_t i = 0; i <= a.size(); ++i) d[i][0] = i;
  for (size_t j = 0; j <= b.size(); ++j) d[0][j] = j;
  for (size_t i = 1; i <= a.size(); ++i)
    for (size_t j = 1; j <= b.size(); ++j) {
      const size_t cost = a[i - 1] == b[j - 1] ? 0 : 1;
      d[i][j] = std::min({d[i - 1][j] + 1, d[i][j - 1] + 1, d[i - 1][j - 1] + cost});
      if (i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1]) d[i][j] = std::min(d[i][j], d[i - 2][j - 2] + 1);
    }
  return d[a.size()][b.size()];
}

}  // namespace

std::vector<std::string> nearest_names(const std::string& typed, const std::vector<std::string>& candidates,
                                       size_t most) {
  // Names from files can be long or many: only compare what could be within the bound.
  const std::string t = lower(typed);
  const size_t bound = std::clamp<size_t>(t.size() / 3, 1, 3);
  std::vector<std::pair<size_t, size_t>> near;  // distance, candidate index
  for (size_t k = 0; k < candidates.size(); ++k) {
    const std::string c = lower(candidates[k]);
    if (c.size() > t.size() + bound || t.size() > c.size() + bound || c.size() > 256) continue;
    if (const size_t d = distance(t, c); d <= bound) near.push_back({d, k});
  }
  std::stable_sort(near.begin(), near.end(), [](const auto& x, const auto& y) { return x.first < y.first; });
  std::vector<std::string> out;
  for (size_t k = 0; k < near.size() && out.size() < most; ++k) out.push_back(candidates[near[k].second]);
  return out;
}

std::string did_you_mean(const std::string& typed, const std::vector<std::string>& candidates, size_t most) {
  const std::vector<std::string> near = nearest_names(typed, candidates, most);
  if (near.empty()) return "";
  std::string s = " (did you mean ";
  for (size_t k = 0; k < near.size(); ++k)
    s += (k == 0 ? "" : k + 1 == near.size() ? " or " : ", ") + ("'" + near[k] + "'");
  return s + "?)";
}

std::string no_joint_message(const Skeleton& skeleton, const std::string& typed) {
  std::vector<std::string> joints;
  for (const Joint& j : skeleton.joints)
    if (!j.end_site) joints.push_back(j.name);
  std::string near = did_you_mean(typed, joints, 3);
  if (!near.empty()) near.pop_back();  // the closing parenthesis: the hint goes inside
  return "no joint named '" + typed + "'" + (near.empty() ? " (" : near + "; ") +
         "`keyanim info FILE --json` lists the joints)";
}

}  // namespace keyanim::cli
