// `orbis settings-keys`: the settings keys the reader accepts (orbis::settingsKeys), for people
// and for tools that check keys before a run (orbis.sweep's study files).
#include <cstdio>
#include <string>

#include "command.hpp"
#include "orbis/io/settings.hpp"
#include "orbis/util/json.hpp"

namespace orbis::cli {
namespace {

int settingsKeysCommand(const std::vector<std::string>& args) {
  ArgParser p("orbis settings-keys [--json]",
              "Lists every key of a settings file that orbis reads: its name, its kind of value and what it sets.\n"
              "Other keys in a file (ORB-SLAM2's Viewer.*, ...) are ignored.");
  p.flag("--json", "print a JSON array of {name, type, meaning}");
  if (!p.parse(args)) return 0;
  if (p.has("--json")) {
    JsonWriter w;
    w.beginArray();
    for (const SettingsKey& k : settingsKeys())
      w.beginObject().field("name", k.name).field("type", k.type).field("meaning", k.meaning).endObject();
    w.endArray();
    std::printf("%s\n", w.str().c_str());
    return 0;
  }
  for (const SettingsKey& k : settingsKeys())
    std::printf("%-36s %-13s %s\n", std::string(k.name).c_str(), std::string(k.type).c_str(),
                std::string(k.meaning).c_str());
  return 0;
}

ORBIS_REGISTER_COMMAND("settings-keys", "the settings keys orbis reads (name, type, meaning)", settingsKeysCommand);

}  // namespace
}  // namespace orbis::cli
