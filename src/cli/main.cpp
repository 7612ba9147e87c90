// The orbis program: a thin dispatcher over the subcommands registered in cli/cmd_*.cpp.
#include <cstdio>
#include <exception>
#include <string>
#include <vector>

#include "command.hpp"
#include "orbis/util/error.hpp"

namespace {

void printUsage(std::FILE* out) { std::fputs(orbis::cli::programUsage().c_str(), out); }

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2 || std::string(argv[1]) == "--help" || std::string(argv[1]) == "-h") {
    printUsage(argc < 2 ? stderr : stdout);
    return argc < 2 ? 2 : 0;
  }
  // `orbis --version` is `orbis version` (src/cli/cmd_version.cpp).
  const std::string name = std::string(argv[1]) == "--version" ? "version" : argv[1];
  const auto& cmds = orbis::cli::commands();
  const auto it = cmds.find(name);
  if (it == cmds.end()) {
    std::fprintf(stderr, "orbis: unknown command '%s'\n\n", name.c_str());
    printUsage(stderr);
    return 2;
  }
  std::vector<std::string> args(argv + 2, argv + argc);
  try {
    return it->second.run(args);
  } catch (const orbis::Error& e) {
    std::fprintf(stderr, "orbis %s: error: %s\n", name.c_str(), e.what());
    return 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "orbis %s: internal error: %s\n", name.c_str(), e.what());
    return 3;
  }
}
