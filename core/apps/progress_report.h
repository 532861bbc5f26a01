// How the CLI shows progress and how it is canceled: a Progress whose callback
// draws a bar on a terminal, prints JSON Lines for the server's worker, or
// stays quiet; and SIGINT/SIGTERM handlers that set its cancel token, so the
// core stops at its next progress update and the CLI exits with 130.
#pragma once

#include <string>

#include "soupuv/progress.h"

namespace soupuv::cli {

enum class ProgressMode { bar, json, none };

// Parses "bar" | "json" | "none"; throws UsageError otherwise.
ProgressMode parse_progress_mode(const std::string& text);

// Builds the Progress for `mode`. `bar` falls back to quiet when stderr is not
// a terminal. The JSON lines are exactly {"stage":"<name>","fraction":<x>}.
Progress make_progress(ProgressMode mode);

// Routes SIGINT and SIGTERM to progress.cancel(); a second signal of the same
// kind gets the default action (so a stuck run can still be killed).
void cancel_on_signals(Progress& progress);

// Ends a progress bar's line (no-op for other modes).
void finish_progress(ProgressMode mode);

}  // namespace soupuv::cli
