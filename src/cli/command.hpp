// src/cli/command.hpp — the orbis program's subcommand registry and argument parser.
//
// Contract: each subcommand lives in its own cli/cmd_<name>.cpp and registers itself with
// ORBIS_REGISTER_COMMAND; main() dispatches on argv[1]. Every subcommand declares its options
// through ArgParser, which gives it --help for free and turns a bad argument into orbis::Error.
#pragma once

#include <functional>
#include <map>
#include <optional>
#include <string>
#include <vector>

namespace orbis::cli {

class ArgParser {
 public:
  ArgParser(std::string usage, std::string description)
      : usage_(std::move(usage)), description_(std::move(description)) {}

  // A boolean switch (--json).
  ArgParser& flag(const std::string& name, const std::string& help);
  // An option that takes a value (--max-dt S); defaultValue empty means "no default".
  ArgParser& option(const std::string& name, const std::string& valueName, const std::string& help,
                    const std::string& defaultValue = {});
  // Positional arguments, in order; the ones past `required` are optional.
  ArgParser& positional(const std::string& name, const std::string& help, bool required = true);

  // Returns false when --help was printed (the caller then returns 0). Throws orbis::Error on
  // unknown options, missing values and missing positionals.
  bool parse(const std::vector<std::string>& args);

  bool has(const std::string& name) const;
  std::string get(const std::string& name) const;  // option value, or its default
  std::optional<std::string> getOptional(const std::string& name) const;
  double getDouble(const std::string& name) const;
  long getInt(const std::string& name) const;
  const std::string& pos(std::size_t i) const { return positionals_.at(i); }
  std::size_t positionalCount() const { return positionals_.size(); }
  std::string helpText() const;

 private:
  struct Opt {
    std::string name, valueName, help, defaultValue;
    bool isFlag = false;
  };
  struct Pos {
    std::string name, help;
    bool required = true;
  };
  const Opt* find(const std::string& name) const;
  std::string usage_, description_;
  std::vector<Opt> opts_;
  std::vector<Pos> posSpec_;
  std::map<std::string, std::string> values_;
  std::vector<std::string> positionals_;
};

struct Command {
  std::string name;
  std::string summary;
  std::function<int(const std::vector<std::string>&)> run;  // args after the subcommand name
};

bool registerCommand(Command command);
// Blocks until SIGINT or SIGTERM (Ctrl-C), e.g. while a viewer serves a finished run.
void waitUntilInterrupted();
const std::map<std::string, Command>& commands();
// What `orbis --help` prints: the usage line and every registered command with its summary.
std::string programUsage();
// What running a command with these arguments prints on standard output, run in-process (its
// exit status discarded): `orbis help` and `orbis completion` read each command's --help so.
std::string capturedOutput(const Command& command, const std::vector<std::string>& args);

}  // namespace orbis::cli

#define ORBIS_CLI_CONCAT_(a, b) a##b
#define ORBIS_CLI_CONCAT(a, b) ORBIS_CLI_CONCAT_(a, b)
#define ORBIS_REGISTER_COMMAND(...) \
  static const bool ORBIS_CLI_CONCAT(orbisCommandRegistered_, __LINE__) = \
      ::orbis::cli::registerCommand(::orbis::cli::Command{__VA_ARGS__})
