#include "command.hpp"

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <thread>
#include <sstream>

#include "orbis/util/error.hpp"

namespace orbis::cli {

ArgParser& ArgParser::flag(const std::string& name, const std::string& help) {
  opts_.push_back({name, "", help, "", true});
  return *this;
}

ArgParser& ArgParser::option(const std::string& name, const std::string& valueName,
                             const std::string& help, const std::string& defaultValue) {
  opts_.push_back({name, valueName, help, defaultValue, false});
  return *this;
}

ArgParser& ArgParser::positional(const std::string& name, const std::string& help, bool required) {
  posSpec_.push_back({name, help, required});
  return *this;
}

const ArgParser::Opt* ArgParser::find(const std::string& name) const {
  for (const auto& o : opts_)
    if (o.name == name) return &o;
  return nullptr;
}

bool ArgParser::parse(const std::vector<std::string>& args) {
  for (std::size_t i = 0; i < args.size(); ++i) {
    const std::string& a = args[i];
    if (a == "--help" || a == "-h") {
      std::fputs(helpText().c_str(), stdout);
      return false;
    }
    if (a.size() > 2 && a.rfind("--", 0) == 0) {
      std::string name = a, inlineValue;
      bool hasInline = false;
      if (auto eq = a.find('='); eq != std::string::npos) {
        name = a.substr(0, eq);
        inlineValue = a.substr(eq + 1);
        hasInline = true;
      }
      const Opt* o = find(name);
      if (!o) throw Error("argument " + name, "", "unknown option (see --help)");
      if (o->isFlag) {
        if (hasInline) throw Error("argument " + name, "", "is a switch and takes no value");
        // A std::string, not "1": GCC 12 at -O3 warns (-Wrestrict, a false positive) on assigning
        // a literal here.
        values_[name] = std::string(1, '1');
      } else if (hasInline) {
        values_[name] = inlineValue;
      } else {
        if (i + 1 >= args.size()) throw Error("argument " + name, "", "expects a value " + o->valueName);
        values_[name] = args[++i];
      }
      continue;
    }
    positionals_.push_back(a);
  }
  std::size_t required = 0;
  for (const auto& p : posSpec_) required += p.required ? 1 : 0;
  if (positionals_.size() < required)
    throw Error("arguments", "", "missing " + posSpec_[positionals_.size()].name + "\nusage: " + usage_);
  if (positionals_.size() > posSpec_.size())
    throw Error("arguments", "", "unexpected argument '" + positionals_[posSpec_.size()] + "'\nusage: " + usage_);
  return true;
}

bool ArgParser::has(const std::string& name) const { return values_.count(name) != 0; }

std::optional<std::string> ArgParser::getOptional(const std::string& name) const {
  if (auto it = values_.find(name); it != values_.end()) return it->second;
  if (const Opt* o = find(name); o && !o->defaultValue.empty()) return o->defaultValue;
  return std::nullopt;
}

std::string ArgParser::get(const std::string& name) const { return getOptional(name).value_or(""); }

double ArgParser::getDouble(const std::string& name) const {
  const std::string v = get(name);
  char* end = nullptr;
  const double d = std::strtod(v.c_str(), &end);
  if (v.empty() || *end != '\0') throw Error("argument " + name, "", "expects a number, got '" + v + "'");
  return d;
}

long ArgParser::getInt(const std::string& name) const {
  const std::string v = get(name);
  char* end = nullptr;
  const long d = std::strtol(v.c_str(), &end, 10);
  if (v.empty() || *end != '\0') throw Error("argument " + name, "", "expects an integer, got '" + v + "'");
  return d;
}

std::string ArgParser::helpText() const {
  std::ostringstream s;
  s << "usage: " << usage_ << "\n\n" << description_ << "\n";
  if (!posSpec_.empty()) {
    s << "\narguments:\n";
    for (const auto& p : posSpec_) s << "  " << p.name << (p.required ? "" : " (optional)") << "\n      " << p.help << "\n";
  }
  s << "\noptions:\n";
  for (const auto& o : opts_) {
    s << "  " << o.name << (o.isFlag ? "" : " " + o.valueName) << "\n      " << o.help;
    if (!o.defaultValue.empty()) s << " (default: " << o.defaultValue << ")";
    s << "\n";
  }
  s << "  --help\n      show this help\n";
  return s.str();
}

static std::map<std::string, Command>& registry() {
  static std::map<std::string, Command> r;
  return r;
}

bool registerCommand(Command command) {
  auto name = command.name;
  registry().emplace(std::move(name), std::move(command));
  return true;
}

const std::map<std::string, Command>& commands() { return registry(); }

std::string programUsage() {
  std::string text =
      "usage: orbis <command> [arguments] [--help]\n\n"
      "orbis — visual SLAM for monocular, stereo and RGB-D cameras (ORB-SLAM2 system).\n\n"
      "commands:\n";
  std::size_t width = 8;
  for (const auto& [name, cmd] : commands()) width = std::max(width, name.size());
  for (const auto& [name, cmd] : commands())
    text += "  " + name + std::string(width - name.size() + 1, ' ') + cmd.summary + "\n";
  text += "\nRun 'orbis help <command>' (or 'orbis <command> --help') for the command's arguments,\n"
          "'orbis --version' for this build's version and configuration.\n";
  return text;
}

std::string capturedOutput(const Command& command, const std::vector<std::string>& args) {
  std::fflush(stdout);
  std::FILE* sink = std::tmpfile();
  if (!sink) throw Error("standard output", "", "cannot create a temporary file to capture a command's help");
  const int saved = ::dup(STDOUT_FILENO);
  ::dup2(::fileno(sink), STDOUT_FILENO);
  try {
    command.run(args);
  } catch (...) {
    // the help text is what matters; a command that refuses the arguments prints none
  }
  std::fflush(stdout);
  ::dup2(saved, STDOUT_FILENO);
  ::close(saved);
  std::string text;
  std::rewind(sink);
  char buffer[4096];
  for (std::size_t n; (n = std::fread(buffer, 1, sizeof buffer, sink)) > 0;) text.append(buffer, n);
  std::fclose(sink);
  return text;
}

namespace {
volatile std::sig_atomic_t interrupted = 0;
extern "C" void onInterrupt(int) { interrupted = 1; }
}  // namespace

void waitUntilInterrupted() {
  std::signal(SIGINT, onInterrupt);
  std::signal(SIGTERM, onInterrupt);
  while (!interrupted) std::this_thread::sleep_for(std::chrono::milliseconds(100));
}

}  // namespace orbis::cli
