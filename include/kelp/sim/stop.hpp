/// \file
/// \brief Stopping a run cleanly: a process-wide stop request that kelp::sim's run loops poll once
/// per step (simulate(), run_scenario(), run_fleet()), and the SIGINT / SIGTERM handlers the
/// programs install to raise it.
///
/// A stopped run finishes the step it is in, closes every file whole (the CSV files end on a full
/// line, run.mcap gets its summary and footer) and returns its summary with `completed` false and
/// the simulated time reached (summary.json's `"completed": false`, `simulated_s`). A program
/// then exits with interrupted_exit_status() (128 + the signal: 130 for SIGINT, 143 for SIGTERM,
/// the shell's convention).
///
/// The library never installs a signal handler by itself: a program calls
/// install_stop_handlers(); a library user (Python's `kelp`, which keeps its own SIGINT handler)
/// passes its own check instead (RunOptions::should_stop, SimulateOptions::should_stop) or calls
/// request_stop(). The request is one lock-free atomic, so the handler is async-signal-safe and
/// any thread may poll it. Part of the optional `kelp::sim` component.
#pragma once

#include "kelp/sim/export.hpp"

namespace kelp {
namespace sim {

/// \brief True once a stop has been requested (request_stop(), or a signal caught by the
/// handlers of install_stop_handlers()), until clear_stop().
/// \return whether a stop is requested (one atomic load; any thread, async-signal-safe)
KELP_SIM_API bool stop_requested() noexcept;

/// \brief The signal that requested the stop (SIGINT, SIGTERM), or 0 when none was requested or
/// request_stop() was called without one.
/// \return the signal's number, or 0
KELP_SIM_API int stop_signal() noexcept;

/// \brief Requests a stop, naming `signal` (0: none). Async-signal-safe: it stores into one
/// lock-free atomic. The first request's signal is kept.
/// \param signal the signal's number (SIGINT, SIGTERM), or 0 for a request without one
KELP_SIM_API void request_stop(int signal = 0) noexcept;

/// \brief Withdraws the request (e.g. between the runs of a test). It does not reinstall
/// handlers that a signal has reset.
KELP_SIM_API void clear_stop() noexcept;

/// \brief Installs the handlers of SIGINT and SIGTERM for a program: the first of either
/// requests a stop (request_stop(signal)) and restores both signals' default action, so that a
/// second one ends the process at once. A signal the program was started with ignored (`nohup`,
/// a background job's SIGINT) stays ignored. For programs only: the library never calls it.
KELP_SIM_API void install_stop_handlers();

/// \brief The exit status of a program whose run was stopped: 128 + stop_signal() (130 for
/// SIGINT, 143 for SIGTERM), or 130 when the stop named no signal.
/// \return the status to pass to exit() or return from main()
KELP_SIM_API int interrupted_exit_status() noexcept;

}  // namespace sim
}  // namespace kelp
