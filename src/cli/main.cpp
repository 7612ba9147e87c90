// The orbis program: a thin dispatcher over the subcommands registered in cli/cmd_*.cpp.
#include <cstdio>
#include <exception>
#include <string>
#include <vector>

#include "command.hpp"
#include "orbis/util/error.hpp"

namespace {

void printUsage() {
  std::printf("usage: orbis <command> [arguments] [--help]\n\n"
              "orbis — visual SLAM for monocular, stereo and RGB-D cameras (ORB-SLAM2 system).\n\n"
              "commands:\n");
  for (const auto& [name, cmd] : orbis::cli::commands()) std::printf("  %-8s %s\n", name.c_str(), cmd.summary.c_str());
  std::printf("\nRun 'orbis <command> --help' for the command's arguments.\n");
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2 || std::string(argv[1]) == "--help" || std::string(argv[1]) == "-h") {
    printUsage();
    return argc < 2 ? 2 : 0;
  }
  const std::string name = argv[1];
  const auto& cmds = orbis::cli::commands();
  const auto it = cmds.find(name);
  if (it == cmds.end()) {
    std::fprintf(stderr, "orbis: unknown command '%s'\n\n", name.c_str());
    printUsage();
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
