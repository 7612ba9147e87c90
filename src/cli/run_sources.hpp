// src/cli/run_sources.hpp — `orbis run video|images|camera`: the frame source its arguments name.
#pragma once

#include <memory>
#include <string>

#include "command.hpp"
#include "orbis/adapters/frame_source.hpp"

namespace orbis::cli {

// video, images and camera: the inputs that are not a benchmark layout.
bool isStreamSourceKind(const std::string& kind);

// Opens the source `kind` names with PATH (p.pos(1), optional for camera) and the options
// --fps, --times, --stereo, --right, --depth, --sensor, --stall and --realtime (a recording
// played as a live camera: paced by its timestamps, newest frame wins). Throws orbis::Error
// naming the file, folder or device.
std::unique_ptr<FrameSource> openStreamSource(const std::string& kind, const ArgParser& p);

// Installs SIGINT/SIGTERM handlers that only raise a flag (async-signal-safe); a second signal
// ends the program at once (the default action is restored by the first).
void catchInterrupts();
bool interruptRequested();

}  // namespace orbis::cli
