// Registry of `dynorb` subcommands. Each subcommand lives in its own apps/cmd_<name>.cc and
// registers itself at static-initialisation time:
//
//   const bool kRegistered = dynorb::RegisterCommand(
//       "eval", 20, [](CLI::App& app) { auto* cmd = app.add_subcommand("eval", "...");
//                                       ...; cmd->callback([opts] { RunEval(*opts); }); });
//
// Callbacks report bad user input by throwing dynorb::InputError; main() prints one message and
// exits non-zero. `order` sorts the subcommands in --help.
#pragma once

#include <functional>
#include <string>

#include <CLI/CLI.hpp>

namespace dynorb {

using CommandSetup = std::function<void(CLI::App&)>;

bool RegisterCommand(const std::string& name, int order, CommandSetup setup);
void AddRegisteredCommands(CLI::App& app);

// Checks for numeric options whose CLI11 defaults mislead. An unsigned option (e.g. --seed) would
// take "-1" as 2^64 - 1; CLI::PositiveNumber reports its range as doubles up to 1.8e308.
CLI::Validator NonNegativeInteger();
CLI::Validator IntAtLeast(int min);

}  // namespace dynorb
