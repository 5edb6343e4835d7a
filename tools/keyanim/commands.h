// The subcommands. Each takes the arguments after its name and returns an exit code (or throws
// cli::Failure). Help text of each lives beside its implementation.
#pragma once
#include <string>
#include <vector>

#include "cli.h"

namespace keyanim::cli {

using Argv = std::vector<std::string>;
int cmd_encode(const Argv& argv, Globals& g);
int cmd_decode(const Argv& argv, Globals& g);
int cmd_info(const Argv& argv, Globals& g);
int cmd_sample(const Argv& argv, Globals& g);
int cmd_plot(const Argv& argv, Globals& g);
int cmd_render(const Argv& argv, Globals& g);
int cmd_eval(const Argv& argv, Globals& g);
int cmd_verify(const Argv& argv, Globals& g);
int cmd_view(const Argv& argv, Globals& g);
int cmd_convert(const Argv& argv, Globals& g);
int cmd_pack(const Argv& argv, Globals& g);
int cmd_list(const Argv& argv, Globals& g);
int cmd_unpack(const Argv& argv, Globals& g);

extern const char* const kEncodeHelp;
extern const char* const kDecodeHelp;
extern const char* const kInfoHelp;
extern const char* const kSampleHelp;
extern const char* const kPlotHelp;
extern const char* const kRenderHelp;
extern const char* const kEvalHelp;
extern const char* const kVerifyHelp;
extern const char* const kViewHelp;
extern const char* const kConvertHelp;
extern const char* const kPackHelp;
extern const char* const kListHelp;
extern const char* const kUnpackHelp;

}  // namespace keyanim::cli
