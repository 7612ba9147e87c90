// orbis version | help COMMAND [ACTION] | completion bash: what a user expects of any program.
//
// The version names the build exactly (git revision, build type, compiler, the OpenCV and Eigen it
// was compiled against, which optional parts are in). `help` and the bash completion are read off
// the command table and each command's own --help, so a new command or option needs no edit here.
#include <Eigen/Core>
#include <cstdio>
#include <regex>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "command.hpp"
#include "orbis/util/error.hpp"
#include "orbis/util/json.hpp"
#include "orbis/version.hpp"

namespace orbis::cli {

const char* gitRevision();  // generated at build time (cmake/BuildInfo.cmake)

namespace {

struct OptionalPart {
  const char* name;
  bool built;
};

std::vector<OptionalPart> optionalParts() {
#ifdef ORBIS_HAS_VIEWER
  constexpr bool kViewer = true;
#else
  constexpr bool kViewer = false;
#endif
  return {{"viewer", kViewer},
          {"python", ORBIS_BUILT_PYTHON != 0},
          {"popcnt", ORBIS_BUILT_POPCNT != 0},
          {"native-arch", ORBIS_BUILT_NATIVE_ARCH != 0}};
}

std::string eigenVersion() {
  return std::to_string(EIGEN_WORLD_VERSION) + "." + std::to_string(EIGEN_MAJOR_VERSION) + "." +
         std::to_string(EIGEN_MINOR_VERSION);
}

int runVersion(const std::vector<std::string>& args) {
  ArgParser p("orbis version [--json]   (also: orbis --version)",
              "Prints the version, the git revision it was built from, the build type, the compiler, the\n"
              "OpenCV and Eigen versions compiled against, and which optional parts were built.");
  p.flag("--json", "print one JSON object instead of text");
  if (!p.parse(args)) return 0;
  const std::string sanitize = ORBIS_BUILT_SANITIZE;
  if (p.has("--json")) {
    JsonWriter w;
    w.beginObject().field("version", versionString()).field("git_revision", gitRevision());
    w.field("build_type", ORBIS_BUILD_TYPE).field("compiler", ORBIS_COMPILER);
    w.field("opencv", ORBIS_OPENCV_VERSION).field("eigen", eigenVersion()).field("sanitize", sanitize);
    w.key("optional_parts").beginObject();
    for (const OptionalPart& part : optionalParts()) w.field(part.name, part.built);
    w.endObject().endObject();
    std::printf("%s\n", w.str().c_str());
    return 0;
  }
  std::string built, missing;
  for (const OptionalPart& part : optionalParts()) (part.built ? built : missing) += std::string(" ") + part.name;
  std::printf("orbis %s\n", versionString());
  std::printf("git revision    %s\n", gitRevision());
  std::printf("build type      %s%s\n", ORBIS_BUILD_TYPE, sanitize.empty() ? "" : (" (sanitize: " + sanitize + ")").c_str());
  std::printf("compiler        %s\n", ORBIS_COMPILER);
  std::printf("OpenCV          %s\n", ORBIS_OPENCV_VERSION);
  std::printf("Eigen           %s\n", eigenVersion().c_str());
  std::printf("built with     %s\n", built.empty() ? " (no optional part)" : built.c_str());
  if (!missing.empty()) std::printf("built without  %s\n", missing.c_str());
  return 0;
}

// The lines of a help text's section ("options:", "actions:"), up to the next blank line.
std::vector<std::string> sectionLines(const std::string& help, const std::string& title) {
  std::vector<std::string> lines;
  std::istringstream in(help);
  bool inside = false;
  for (std::string line; std::getline(in, line);) {
    if (line == title) {
      inside = true;
    } else if (inside) {
      if (line.empty()) break;
      lines.push_back(line);
    }
  }
  return lines;
}

std::vector<std::string> optionsIn(const std::string& help) {
  std::vector<std::string> options;
  static const std::regex option(R"(^  (--[A-Za-z0-9][A-Za-z0-9-]*))");
  for (const std::string& line : sectionLines(help, "options:"))
    if (std::smatch m; std::regex_search(line, m, option)) options.push_back(m[1]);
  return options;
}

std::vector<std::string> actionsIn(const std::string& help) {
  std::vector<std::string> actions;
  static const std::regex action(R"(^  ([a-z][a-z0-9-]*)( |$))");
  for (const std::string& line : sectionLines(help, "actions:"))
    if (std::smatch m; std::regex_search(line, m, action)) actions.push_back(m[1]);
  return actions;
}

const Command& commandNamed(const std::string& name) {
  const auto it = commands().find(name);
  if (it == commands().end()) throw Error("argument COMMAND", "", "unknown command '" + name + "' (orbis --help lists them)");
  return it->second;
}

int runHelp(const std::vector<std::string>& args) {
  if (args.empty()) {
    std::fputs(programUsage().c_str(), stdout);
    return 0;
  }
  if (args[0] == "--help" || args[0] == "-h") {
    std::printf("usage: orbis help [COMMAND [ACTION]]\n\nPrints the commands, or a command's (or its action's) arguments and options.\n");
    return 0;
  }
  std::vector<std::string> forward(args.begin() + 1, args.end());
  forward.push_back("--help");
  return commandNamed(args[0]).run(forward);
}

std::string quoted(const std::vector<std::string>& words) {
  std::string s;
  for (const auto& w : words) s += (s.empty() ? "" : " ") + w;
  return s;
}

// One bash function: the command names, then per command (and per action) its options, all read
// from the command table and the commands' own --help when the script is generated.
std::string bashCompletion() {
  std::vector<std::string> names;
  std::ostringstream cases;
  for (const auto& [name, cmd] : commands()) {
    names.push_back(name);
    if (name == "completion" || name == "help") continue;
    const std::string help = capturedOutput(cmd, {"--help"});
    const std::vector<std::string> actions = actionsIn(help);
    if (actions.empty()) {
      cases << "    " << name << ") words=\"" << quoted(optionsIn(help)) << "\" ;;\n";
      continue;
    }
    cases << "    " << name << ")\n      if ((cword == 2)); then words=\"" << quoted(actions) << "\"\n      else case ${COMP_WORDS[2]} in\n";
    for (const std::string& action : actions)
      cases << "        " << action << ") words=\"" << quoted(optionsIn(capturedOutput(cmd, {action, "--help"}))) << "\" ;;\n";
    cases << "      esac; fi ;;\n";
  }
  std::ostringstream s;
  s << "# bash completion for orbis " << versionString() << ", generated by `orbis completion bash` from its\n"
    << "# command table. Install: orbis completion bash > ~/.local/share/bash-completion/completions/orbis\n"
    << "# (or `source <(orbis completion bash)` in ~/.bashrc).\n"
    << "_orbis() {\n"
    << "  local cur=${COMP_WORDS[COMP_CWORD]} cword=$COMP_CWORD words=\"\"\n"
    << "  if ((cword == 1)); then\n"
    << "    COMPREPLY=($(compgen -W \"" << quoted(names) << " --help --version\" -- \"$cur\"))\n"
    << "    return\n"
    << "  fi\n"
    << "  case ${COMP_WORDS[1]} in\n"
    << "    help|completion)\n"
    << "      if ((cword == 2)); then words=\"" << quoted(names) << " bash\"; fi ;;\n"
    << cases.str() << "  esac\n"
    << "  if [[ $cur == -* || (-n $words && $words != --*) ]]; then\n"
    << "    COMPREPLY=($(compgen -W \"$words --help\" -- \"$cur\"))\n"
    << "  else\n"
    << "    COMPREPLY=($(compgen -f -- \"$cur\"))\n"
    << "  fi\n"
    << "}\n"
    << "complete -o filenames -o bashdefault -F _orbis orbis\n";
  return s.str();
}

int runCompletion(const std::vector<std::string>& args) {
  ArgParser p("orbis completion bash",
              "Prints a bash completion script for orbis's commands, actions and options.\n"
              "Install: orbis completion bash > ~/.local/share/bash-completion/completions/orbis");
  p.positional("SHELL", "bash (the only shell supported)");
  if (!p.parse(args)) return 0;
  if (p.pos(0) != "bash") throw Error("argument SHELL", "", "only bash is supported, got '" + p.pos(0) + "'");
  std::fputs(bashCompletion().c_str(), stdout);
  return 0;
}

}  // namespace

ORBIS_REGISTER_COMMAND("version", "the version, git revision and build configuration (also --version)", runVersion);
ORBIS_REGISTER_COMMAND("help", "the commands, or one command's arguments and options", runHelp);
ORBIS_REGISTER_COMMAND("completion", "a bash completion script generated from the commands' options", runCompletion);

}  // namespace orbis::cli
