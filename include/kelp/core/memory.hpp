/// \file
/// \brief The memory-visitor protocol: how an object that remembers something between calls (a
/// PID's integral, a filter's covariance, a sensor's random stream) lists that memory once, so
/// that a run's checkpoint saves it and restores it bit for bit (kelp::sim's run checkpoints,
/// docs/checkpoints.md) without the object knowing any file format.
///
/// Such an object has `visit_memory(v)`, const and non-const, which calls, in a fixed order:
///
///     v(x, y, ...)             each a double, bool, int, long, std::size_t, std::uint64_t,
///                              Eigen matrix (its current size), Eigen::Quaternion,
///                              std::mt19937_64, std::array of these, or an object with its own
///                              visit_memory (visited in turn)
///     v.bounded(i, hi)         an integer that indexes something: 0 <= i <= hi
///     v.choice(e, n)           an enumeration with the values 0 ... n - 1
///     v.list(vector, max, f)   a std::vector whose length may change (at most max): f(element)
///                              visits each element
///
/// A saving visitor receives const references and writes them; a restoring one receives
/// references and overwrites them, checking every length, bound and choice against the object
/// it restores (a restored object never indexes out of range, whatever the bytes). Settings and
/// parameters are not memory: the object is built from them as before, then restored.
///
/// KELP_MEMORY(a, b, ...) declares both members for an object whose memory is a list of plain
/// members (the common case); KELP_MEMORY_BY(f) declares them as calls of the class's own static
/// template `f(self, v)`, `self` the object (const when saving), for memory that takes more
/// (bounds, lists, loops over members).
#pragma once

/// \brief Declares `visit_memory(v)` (const and non-const) visiting the members given, in order:
/// `v(a, b, ...)` (see the file comment).
#define KELP_MEMORY(...)          \
  template <class V>              \
  void visit_memory(V& v) {       \
    v(__VA_ARGS__);               \
  }                               \
  template <class V>              \
  void visit_memory(V& v) const { \
    v(__VA_ARGS__);               \
  }

/// \brief Declares `visit_memory(v)` (const and non-const) as `f(*this, v)`, `f` a static member
/// template of the class taking the object (const or not) and the visitor (see the file comment).
#define KELP_MEMORY_BY(f)         \
  template <class V>              \
  void visit_memory(V& v) {       \
    f(*this, v);                  \
  }                               \
  template <class V>              \
  void visit_memory(V& v) const { \
    f(*this, v);                  \
  }
