#pragma once
// PLCEMUD_PARENT_PID: a program that starts plcemud for a while (the pytest kit) asks it to stop
// when that program dies, however it dies — SIGKILL included, when nothing of the program runs
// to stop it (docs/testing.md, "When the test process dies").

namespace plcemu::daemon {

/// With PLCEMUD_PARENT_PID set to the pid of the process that started plcemud: on Linux, asks
/// the kernel to send SIGTERM (a normal stop) when that parent exits. Returns false when the
/// parent is gone already (it died before the request was made): the daemon should not start.
/// Unset, empty or not a number: nothing happens (a warning for a bad value).
bool watch_parent() noexcept;

}  // namespace plcemu::daemon
