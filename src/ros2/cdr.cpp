// CDR serialisation (kelp/sim/ros2/cdr.hpp): the writer's and reader's non-template members.
#include "kelp/sim/ros2/cdr.hpp"

namespace kelp {
namespace ros2 {

CdrWriter::CdrWriter(std::vector<std::uint8_t>& out) : out_(out) {
  // Cleared, then the header: assign() (clear() then insert() draws GCC 12's false
  // -Warray-bounds / -Wstringop-overflow once out of line).
  out_.assign(cdr_le_header.begin(), cdr_le_header.end());
}

void CdrWriter::align(std::size_t a) {
  const std::size_t offset = out_.size() - cdr_le_header.size();
  const std::size_t pad = (a - offset % a) % a;
  out_.insert(out_.end(), pad, std::uint8_t{0});
}

void CdrWriter::put(const void* p, std::size_t n) {
  static_assert(sizeof(double) == 8 && sizeof(float) == 4, "IEEE 754 binary32/64 expected");
  const auto* b = static_cast<const std::uint8_t*>(p);
  out_.insert(out_.end(), b, b + n);  // the host is little endian (checked in serialize)
}

CdrReader::CdrReader(const std::uint8_t* data, std::size_t n) : data_(data), n_(n) {
  if (n < 4 || data[0] != 0x00 || data[1] != 0x01)
    throw kelp::error("CDR: not little-endian plain CDR (encapsulation header 00 01)");
  pos_ = 4;
}

void CdrReader::align(std::size_t a) {
  const std::size_t offset = pos_ - 4;
  pos_ += (a - offset % a) % a;
  if (pos_ > n_) throw kelp::error("CDR: data truncated");
}

void CdrReader::need(std::size_t k) const {
  if (k > n_ - pos_) throw kelp::error("CDR: data truncated");
}

}  // namespace ros2
}  // namespace kelp
