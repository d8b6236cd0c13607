/// \file
/// \brief CDR serialisation of the ROS 2 messages (kelp/sim/ros2/messages.hpp): the bytes a ROS 2
/// node puts on the wire and rosbag2 stores, XCDR1 little endian.
///
/// The rules (OMG DDS-XTypes 1.3, §7.4.3 "Extended CDR representation (encoding version 1)",
/// the plain CDR of OMG CORBA 3.4 Part 2, §9.3, as ROS 2's rmw layers use it):
///   - a 4-byte encapsulation header first: representation identifier CDR_LE = 0x00 0x01, then
///     two option bytes 0x00 0x00;
///   - each primitive is aligned to its own size (1, 2, 4 or 8 bytes: XCDR1 aligns 8-byte types
///     to 8) relative to the first byte after the encapsulation header, with zero padding;
///   - bool and uint8 take 1 byte (bool 0 or 1); float32/float64 are IEEE 754;
///   - a string is a uint32 length that counts the terminating NUL, its bytes, and the NUL;
///   - a sequence (`T[]`) is a uint32 element count and its elements; a fixed array (`T[N]`)
///     its N elements only; a nested message its fields in order.
#pragma once

#include <array>
#include <cstdint>
#include <cstring>
#include <string>
#include <type_traits>
#include <vector>

#include "kelp/core/error.hpp"
#include "kelp/sim/export.hpp"
#include "kelp/sim/ros2/messages.hpp"

namespace kelp {
namespace ros2 {

/// \brief The encapsulation header of little-endian plain CDR (CDR_LE).
inline constexpr std::array<std::uint8_t, 4> cdr_le_header = {0x00, 0x01, 0x00, 0x00};

/// \brief Appends a message's CDR bytes to a byte buffer (kept by the caller, so that its
/// capacity is reused from message to message).
class KELP_SIM_API CdrWriter {
 public:
  /// \brief Starts a message in `out` (cleared, then the encapsulation header).
  /// \param out the buffer, kept by reference: it must outlive the writer
  explicit CdrWriter(std::vector<std::uint8_t>& out);

  /// \brief Writes a primitive, string, sequence, fixed array or message.
  /// \tparam T bool, an arithmetic type, std::string, std::vector, std::array or a message
  /// struct of messages.hpp \param v the value, appended with its alignment padding
  template <class T>
  void operator()(const T& v) {
    if constexpr (std::is_same_v<T, bool>) {
      out_.push_back(v ? 1 : 0);
    } else if constexpr (std::is_arithmetic_v<T>) {
      align(sizeof(T));
      put(&v, sizeof(T));
    } else if constexpr (std::is_same_v<T, std::string>) {
      const auto n = static_cast<std::uint32_t>(v.size() + 1);
      (*this)(n);
      put(v.c_str(), n);  // the bytes and the NUL
    } else if constexpr (detail::is_vector<T>::value) {
      (*this)(static_cast<std::uint32_t>(v.size()));
      for (const auto& e : v) (*this)(e);
    } else if constexpr (is_std_array<T>::value) {
      for (const auto& e : v) (*this)(e);
    } else {
      T::fields(v, *this);
    }
  }

 private:
  /// \cond PRIVATE
  template <class T>
  struct is_std_array : std::false_type {};
  template <class T, std::size_t N>
  struct is_std_array<std::array<T, N>> : std::true_type {};
  void align(std::size_t a);
  void put(const void* p, std::size_t n);
  std::vector<std::uint8_t>& out_;
  /// \endcond
};

/// \brief Reads a message back from its CDR bytes (tests, and a check of what was written).
class KELP_SIM_API CdrReader {
 public:
  /// \brief Reads from `n` bytes at `data`.
  /// \param data the bytes (not copied: they must outlive the reader) \param n their count
  /// \throws kelp::error when the encapsulation header is not CDR_LE.
  CdrReader(const std::uint8_t* data, std::size_t n);

  /// \brief Reads a primitive, string, sequence, fixed array or message.
  /// \throws kelp::error on truncated or malformed data.
  /// \tparam T as CdrWriter's \param v the value, overwritten
  template <class T>
  void operator()(T& v) {
    if constexpr (std::is_same_v<T, bool>) {
      need(1);
      v = data_[pos_++] != 0;
    } else if constexpr (std::is_arithmetic_v<T>) {
      align(sizeof(T));
      need(sizeof(T));
      std::memcpy(&v, data_ + pos_, sizeof(T));
      pos_ += sizeof(T);
    } else if constexpr (std::is_same_v<T, std::string>) {
      std::uint32_t len = 0;
      (*this)(len);
      need(len);
      if (len == 0 || data_[pos_ + len - 1] != 0)
        throw kelp::error("CDR: a string without its terminating NUL");
      v.assign(reinterpret_cast<const char*>(data_ + pos_), len - 1);
      pos_ += len;
    } else if constexpr (detail::is_vector<T>::value) {
      std::uint32_t count = 0;
      (*this)(count);
      if (count > n_ - pos_) throw kelp::error("CDR: a sequence longer than the data");
      v.resize(count);
      for (auto& e : v) (*this)(e);
    } else if constexpr (is_std_array<T>::value) {
      for (auto& e : v) (*this)(e);
    } else {
      T::fields(v, *this);
    }
  }

  /// \brief Bytes not read yet. \return the count [bytes]
  std::size_t remaining() const { return n_ - pos_; }

 private:
  /// \cond PRIVATE
  template <class T>
  struct is_std_array : std::false_type {};
  template <class T, std::size_t N>
  struct is_std_array<std::array<T, N>> : std::true_type {};
  void align(std::size_t a);
  void need(std::size_t k) const;
  const std::uint8_t* data_;
  std::size_t n_, pos_;
  /// \endcond
};

/// \brief Message `m` as CDR bytes (encapsulation header included) in `out` (cleared first;
/// its capacity is kept, so a reused buffer does not allocate once large enough).
/// \tparam M a message struct of messages.hpp \param m the message \param out the bytes
/// \throws kelp::error on a big-endian host.
template <class M>
void serialize(const M& m, std::vector<std::uint8_t>& out) {
  const std::uint16_t probe = 1;
  std::uint8_t first = 0;
  std::memcpy(&first, &probe, 1);
  if (first != 1) throw kelp::error("CDR: kelp's CDR writer needs a little-endian host");
  CdrWriter w(out);
  w(m);
}

/// \brief Message `m` from CDR bytes (the whole buffer must be used, up to 3 bytes of final
/// padding).
/// \throws kelp::error on a wrong header, truncated data or trailing bytes.
/// \tparam M a message struct of messages.hpp
/// \param data the bytes, encapsulation header first \param n their count
/// \param m the message, overwritten (partly, when it throws)
template <class M>
void deserialize(const std::uint8_t* data, std::size_t n, M& m) {
  CdrReader r(data, n);
  r(m);
  if (r.remaining() > 3) throw kelp::error("CDR: trailing bytes after the message");
}

}  // namespace ros2
}  // namespace kelp
