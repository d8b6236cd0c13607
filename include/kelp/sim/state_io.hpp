/// \file
/// \brief State files: the coupled system's state (the tethered pair's
/// kelp::system::SystemState, a fleet's kelp::system::FleetState) saved as bytes or to a file
/// and loaded back, bit for bit (docs/state-files.md has the format byte by byte).
///
/// Everything in a state that influences a future step is saved: the clocks (with the tethers'
/// compensated-sum carries), the vehicles' poses, velocities and last accelerations, the point
/// masses', the propulsion (each thruster's lagged thrust, the battery's counters and last
/// voltage), and each tether's nodes with its integrator history (previous positions,
/// velocities and step, the implicit steps' kept Newton matrix), its parted segments and its
/// winch (segment 0's length, the payout rate). Doubles are saved as their IEEE-754 bits, so
/// after `load_state(save_state(s), model)` stepping the loaded state gives bit-identical
/// results to stepping `s` (with a winch, once system::fit_workspace has lent the workspace the
/// state's node count).
///
/// The reader treats its input as untrusted: a truncated or corrupted file (CRC-32 over every
/// byte), another format, kind or system, NaN or infinity where a step refuses them, or an
/// absurd length is refused with a kelp::sim::state_error naming what is wrong, and nothing is
/// allocated past what the input holds. Part of the compiled `kelp::sim` component.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>

#include "kelp/core/error.hpp"
#include "kelp/sim/export.hpp"
#include "kelp/sim/instantiation.hpp"
#include "kelp/sim/state_error.hpp"
#include "kelp/system/fleet.hpp"
#include "kelp/system/system.hpp"

namespace kelp {
namespace sim {

/// \brief The pair's state as a state file's bytes.
/// \param state the state (NED positions [m], body velocities, clocks [s])
/// \return the file's bytes (binary, docs/state-files.md)
/// \throws state_error when the state could not be loaded back (sizes that do not fit together,
/// NaN or infinity where a step refuses them, clocks that differ: the loader's checks).
KELP_SIM_API std::string save_state(const kelp::system::SystemStated& state);
/// \brief A fleet's state as a state file's bytes. \throws state_error as the pair's.
/// \param state the fleet's state \return the file's bytes (binary, docs/state-files.md)
KELP_SIM_API std::string save_state(const kelp::system::FleetStated& state);

/// \brief The pair's state from a state file's bytes, checked against `model`: its tether's
/// node count (the model's, or within its winch's range), the propulsion's thruster counts, no
/// winch length without a winch. With a winch, call system::fit_workspace(model, ws, state)
/// before its first step.
/// \param bytes the file's bytes (untrusted) \param model the system it is for
/// \param input names the input in errors
/// \return the state, bit for bit as saved
/// \throws state_error naming what is wrong (nothing else is changed).
KELP_SIM_API kelp::system::SystemStated load_state(std::string_view bytes,
                                                   const kelp::system::SystemModeld& model,
                                                   const std::string& input = "state");
/// \brief A fleet's state from a state file's bytes, checked against `model` (its vehicle, point
/// mass and tether counts, each tether's node count, each vehicle's thrusters). With winches,
/// call system::fit_workspace(model, ws, state) before its first step.
/// \param bytes the file's bytes (untrusted) \param model the fleet it is for
/// \param input names the input in errors \return the state, bit for bit as saved
/// \throws state_error naming what is wrong.
KELP_SIM_API kelp::system::FleetStated load_state(std::string_view bytes,
                                                  const kelp::system::FleetModeld& model,
                                                  const std::string& input = "state");

/// \brief The pair's state from a state file's bytes, checked on its own (sizes that fit
/// together, finite where a step needs it, equal clocks) but not against a system: the step
/// then checks what depends on the system (the node count, the thruster counts). For a reader
/// that has no model at hand (Python's pickle).
/// \param bytes the file's bytes (untrusted) \param input names the input in errors
/// \return the state, bit for bit as saved
/// \throws state_error naming what is wrong.
KELP_SIM_API kelp::system::SystemStated load_system_state(std::string_view bytes,
                                                          const std::string& input = "state");
/// \brief A fleet's state from a state file's bytes, checked on its own (see load_system_state).
/// \param bytes the file's bytes (untrusted) \param input names the input in errors
/// \return the state, bit for bit as saved
/// \throws state_error naming what is wrong.
KELP_SIM_API kelp::system::FleetStated load_fleet_state(std::string_view bytes,
                                                        const std::string& input = "state");

/// \brief Writes save_state(state) to `path` atomically: into a new file beside it, flushed to
/// disk (fsync), then renamed over `path` (and the directory flushed), so that `path` holds
/// either its old content or the whole new state, whatever happens meanwhile.
/// \throws state_error for a state that cannot be saved; kelp::error naming the path when the
/// file cannot be written (`path` is then unchanged and no temporary file is left).
/// \param path the file to write \param state the state
KELP_SIM_API void save_state_file(const std::string& path, const kelp::system::SystemStated& state);
/// \brief Writes a fleet's state to `path` atomically (see the pair's).
/// \param path the file to write \param state the fleet's state
/// \throws state_error for a state that cannot be saved; kelp::error naming the path when the
/// file cannot be written.
KELP_SIM_API void save_state_file(const std::string& path, const kelp::system::FleetStated& state);

/// \brief load_state of the file `path` (errors name the path).
/// \param path the file to read (at most max_state_file_bytes) \param model the system it is for
/// \return the state
/// \throws kelp::error naming the path when it cannot be read; state_error as load_state (also
/// for a file larger than max_state_file_bytes).
KELP_SIM_API kelp::system::SystemStated load_state_file(const std::string& path,
                                                        const kelp::system::SystemModeld& model);
/// \brief load_state of a fleet's file `path` (errors name the path).
/// \param path the file to read (at most max_state_file_bytes) \param model the fleet it is for
/// \return the state
/// \throws kelp::error naming the path when it cannot be read; state_error as load_state.
KELP_SIM_API kelp::system::FleetStated load_state_file(const std::string& path,
                                                       const kelp::system::FleetModeld& model);

/// \brief The largest state file the file reader takes [bytes] (a fleet of 60-node tethers
/// needs ~20 kB per tether).
inline constexpr std::uint64_t max_state_file_bytes = std::uint64_t(1) << 30;

}  // namespace sim
}  // namespace kelp
