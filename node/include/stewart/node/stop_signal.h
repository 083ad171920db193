#pragma once

namespace stewart {

/// Installs SIGINT/SIGTERM handlers that only set a flag, so node loops can
/// finish their current message and exit cleanly.
void InstallStopSignalHandlers();
bool StopRequested();
void RequestStop();

}  // namespace stewart
