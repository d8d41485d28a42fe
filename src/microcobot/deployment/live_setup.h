#pragma once
/// @file
/// The live platform's parameters a ServeConfig describes: the platform's configuration (its file
/// loaded), the scene (a built-in one, a scene file, or with `cell` one part of a batch and the
/// task the console supervises on it). No thread, no socket: what the Deployment builds from.

#include "microcobot/deployment/serve_config.h"
#include "microcobot/live/live_platform.h"

namespace mc::deployment {

/// The live parameters of `config`'s platform and scene. `log` receives the cell part's summary.
/// Throws mc::UsageError (a cell-only field without `cell`, a part outside the batch), mc::InvalidInput
/// (a scene that is neither built in nor a file, an unreadable file), mc::InvalidParams.
live::LiveParams live_params(const ServeConfig& config, const Log& log);

}  // namespace mc::deployment
