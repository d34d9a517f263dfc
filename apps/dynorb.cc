// dynorb: one CLI, one subcommand per job (see README.md). Thin: parsing and error reporting only.
#include <iostream>

#include <CLI/CLI.hpp>

#include "command_registry.h"
#include "dynorb/core/error.h"

int main(int argc, char** argv) {
  CLI::App app{"dynorb: RGB-D SLAM that keeps moving people and objects out of the map"};
  app.require_subcommand(1);
  app.set_version_flag("--version", "dynorb 0.1.0");
  dynorb::AddRegisteredCommands(app);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  } catch (const dynorb::InputError& e) {
    std::cerr << "dynorb: error: " << e.what() << std::endl;
    return 2;
  } catch (const std::exception& e) {
    std::cerr << "dynorb: error: " << e.what() << std::endl;
    return 1;
  }
  return 0;
}
