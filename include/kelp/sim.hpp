/// \file
/// \brief kelp::sim, the compiled library the programs sit on: scenario files, the world a
/// scenario builds, the closed loop (kelp's controllers flying the tethered pair), its typed
/// summary, the run's outputs (CSV log, run.mcap, replay.html), a gym-style environment's core
/// (pair_env.hpp) and a batch of worlds on a thread pool (batch.hpp).
///
/// Link the target kelp::sim, found with `find_package(kelp CONFIG REQUIRED COMPONENTS sim)`; its
/// headers declare, the library (built once, src/) defines, so a program on it compiles in
/// seconds. Not included by kelp/kelp.hpp.
#pragma once

#include "kelp/sim/batch.hpp"
#include "kelp/sim/closed_loop.hpp"
#include "kelp/sim/entanglement.hpp"
#include "kelp/sim/heightfield_file.hpp"
#include "kelp/sim/instantiation.hpp"
#include "kelp/sim/navigation.hpp"
#include "kelp/sim/pair_env.hpp"
#include "kelp/sim/replay.hpp"
#include "kelp/sim/ros2.hpp"
#include "kelp/sim/run.hpp"
#include "kelp/sim/run_log.hpp"
#include "kelp/sim/scenario.hpp"
#include "kelp/sim/scenario_reader.hpp"
#include "kelp/sim/state_io.hpp"
#include "kelp/sim/stop.hpp"
#include "kelp/sim/summary.hpp"
#include "kelp/sim/turn_counter.hpp"
#include "kelp/sim/version.hpp"
#include "kelp/sim/world.hpp"
