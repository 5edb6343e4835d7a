// The shared BVH corpus (KEYANIM_CORPUS_DIR, beside the repository). A user's clone has no
// ../shared, so callers skip their corpus tests when the list comes back empty.
#pragma once
#include <algorithm>
#include <filesystem>
#include <system_error>
#include <vector>

namespace keyanim::test {

inline std::filesystem::path corpus_dir() { return std::filesystem::path(KEYANIM_CORPUS_DIR); }

// Every *.bvh under the corpus directory, subfolders included, sorted; empty if it is absent.
inline std::vector<std::filesystem::path> corpus_bvh_files() {
  std::vector<std::filesystem::path> files;
  std::error_code ec;
  if (!std::filesystem::is_directory(corpus_dir(), ec)) return files;
  for (auto it = std::filesystem::recursive_directory_iterator(corpus_dir(), ec);
       !ec && it != std::filesystem::recursive_directory_iterator(); it.increment(ec)) {
    if (it->is_regular_file(ec) && it->path().extension() == ".bvh") files.push_back(it->path());
  }
  std::sort(files.begin(), files.end());
  return files;
}

// The line a corpus test prints when it cannot run: CTest marks a test whose output holds it as
// skipped (tests/CMakeLists.txt, SKIP_REGULAR_EXPRESSION), and scripts/test.sh says why.
#define KEYANIM_CORPUS_SKIP_MARK "keyanim-corpus-skip"
#define KEYANIM_SKIP_CORPUS_TEST(what) MESSAGE(KEYANIM_CORPUS_SKIP_MARK ": " << (what) << " not found")

}  // namespace keyanim::test
