// Running one job per input file on several threads, with a progress bar on a terminal, going
// on past failures. Used by the commands that accept directories.
#pragma once
#include <functional>
#include <string>
#include <vector>

#include "cli.h"

namespace keyanim::cli {

// Expands directories into their files of these extensions (lower case; recursively, sorted;
// any case of the extension matches); files stay as given.
std::vector<std::string> expand_inputs(const std::vector<std::string>& inputs,
                                       const std::vector<std::string>& extensions = {".bvh"});

// Runs job(i) for every i < count on `threads` threads (0: all cores). A job reports failure
// by throwing cli::Failure; the failure is printed (unless silenced by the caller) and the
// others go on. Returns the exit code of the first failure by input order, or kOk.
int run_batch(size_t count, unsigned threads, const Globals& g, const std::function<void(size_t)>& job,
              const std::vector<std::string>& names);

// -j N: 0 means one thread per core; more than the cores is clamped to them.
unsigned thread_count(const Args& args);

}  // namespace keyanim::cli
