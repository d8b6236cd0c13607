// The MCAP writer's file structure, read back record by record with a reader written here from
// the specification (mcap.dev/spec), CRCs included; the same file is also read by @mcap/core in
// the npm check (tests/ros2/node).
#include <catch2/catch.hpp>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>

#include "kelp/sim/ros2/mcap.hpp"

namespace r2 = kelp::ros2;

namespace kelp_test {
extern long allocations;  // count_allocations.cpp
}

namespace {
std::vector<std::uint8_t> slurp(const std::filesystem::path& p) {
  std::ifstream f(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(f), std::istreambuf_iterator<char>()};
}
struct Cursor {
  const std::vector<std::uint8_t>& b;
  std::size_t pos;
  std::uint64_t u(int bytes) {
    std::uint64_t v = 0;
    for (int i = 0; i < bytes; ++i) v |= std::uint64_t(b.at(pos + i)) << (8 * i);
    pos += bytes;
    return v;
  }
  std::string str() {
    const auto n = u(4);
    std::string s(b.begin() + long(pos), b.begin() + long(pos + n));
    pos += n;
    return s;
  }
};
struct Record {
  std::uint8_t op;
  std::size_t start, content, end;  // record start, content start, end
};
std::vector<Record> records(const std::vector<std::uint8_t>& b, std::size_t from, std::size_t to) {
  std::vector<Record> r;
  Cursor c{b, from};
  while (c.pos < to) {
    Record x;
    x.start = c.pos;
    x.op = std::uint8_t(c.u(1));
    const auto len = c.u(8);
    x.content = c.pos;
    x.end = c.pos + len;
    r.push_back(x);
    c.pos = x.end;
  }
  return r;
}
}  // namespace

TEST_CASE("CRC32 is zlib's (the check value of \"123456789\")", "[ros2][mcap]") {
  CHECK(r2::crc32("123456789", 9) == 0xCBF43926u);
  CHECK(r2::crc32("", 0) == 0u);
  // Continuing a CRC over a split buffer gives the CRC of the whole.
  CHECK(r2::crc32("6789", 4, r2::crc32("12345", 5)) == 0xCBF43926u);
}

TEST_CASE("McapWriter: magic, header, chunks with indexes, summary, footer", "[ros2][mcap]") {
  const std::filesystem::path path = "test_ros2_mcap.mcap";
  r2::McapWriter::Options opt;
  opt.chunk_size = 200;  // several chunks
  r2::McapWriter w(path, opt);
  const auto s = w.add_schema("std_msgs/msg/Header", "ros2msg", "string frame_id\n");
  const auto c1 = w.add_channel(s, "/a", "cdr", {{"k", "v"}});
  const auto c2 = w.add_channel(s, "/b", "cdr");
  CHECK(c1 == 1);
  CHECK(c2 == 2);
  std::vector<std::uint8_t> payload(40, 0xAB);
  for (int i = 0; i < 30; ++i)
    w.write(i % 3 == 0 ? c2 : c1, std::uint32_t(i), 1000u * std::uint64_t(i), payload.data(),
            payload.size());
  w.close();
  const auto b = slurp(path);

  // Magic at both ends.
  REQUIRE(b.size() > 16);
  CHECK(std::equal(r2::mcap_magic.begin(), r2::mcap_magic.end(), b.begin()));
  CHECK(std::equal(r2::mcap_magic.begin(), r2::mcap_magic.end(), b.end() - 8));
  // Footer: the last record before the closing magic (1 + 8 + 20 bytes).
  Cursor f{b, b.size() - 8 - 29};
  REQUIRE(f.u(1) == 0x02);
  REQUIRE(f.u(8) == 20);
  const auto summary_start = f.u(8), offsets_start = f.u(8), summary_crc = f.u(4);
  CHECK(summary_crc == r2::crc32(b.data() + summary_start, b.size() - 8 - 4 - summary_start));
  // The data section: header first, data end last, with its CRC of everything before it.
  const auto data = records(b, 8, summary_start);
  REQUIRE(data.front().op == 0x01);
  Cursor h{b, data.front().content};
  CHECK(h.str() == "ros2");
  CHECK(h.str() == "kelp");
  REQUIRE(data.back().op == 0x0F);
  CHECK(Cursor{b, data.back().content}.u(4) == r2::crc32(b.data(), data.back().start));
  // Chunks: their CRC, and each followed by one message index per channel in it, whose offsets
  // point at Message records with the indexed log time.
  int chunks = 0, messages = 0;
  std::map<std::size_t, std::size_t> chunk_at;  // file offset → records start
  for (std::size_t i = 0; i < data.size(); ++i) {
    if (data[i].op != 0x06) continue;
    ++chunks;
    Cursor c{b, data[i].content};
    const auto t0 = c.u(8), t1 = c.u(8), usize = c.u(8), crc = c.u(4);
    CHECK(c.str().empty());  // uncompressed
    CHECK(c.u(8) == usize);
    const std::size_t recs = c.pos;
    chunk_at[data[i].start] = recs;
    CHECK(crc == r2::crc32(b.data() + recs, usize));
    std::map<std::uint16_t, int> in_chunk;
    for (const auto& m : records(b, recs, recs + usize)) {
      REQUIRE(m.op == 0x05);
      Cursor mc{b, m.content};
      ++in_chunk[std::uint16_t(mc.u(2))];
      mc.u(4);
      const auto t = mc.u(8);
      CHECK(t >= t0);
      CHECK(t <= t1);
      ++messages;
    }
    std::size_t k = i + 1;
    for (; k < data.size() && data[k].op == 0x07; ++k) {
      Cursor mi{b, data[k].content};
      const auto ch = std::uint16_t(mi.u(2));
      const auto n = mi.u(4) / 16;
      CHECK(int(n) == in_chunk[ch]);
      for (std::uint64_t e = 0; e < n; ++e) {
        const auto t = mi.u(8), off = mi.u(8);
        Cursor m{b, recs + off};
        REQUIRE(m.u(1) == 0x05);
        m.u(8);
        CHECK(m.u(2) == ch);
        m.u(4);
        CHECK(m.u(8) == t);
      }
    }
    CHECK(k - i - 1 == in_chunk.size());
  }
  CHECK(chunks > 1);
  CHECK(messages == 30);
  // The summary: schema, channel, statistics, chunk index groups, then one summary offset each.
  const auto summary = records(b, summary_start, offsets_start);
  std::vector<std::uint8_t> ops;
  for (const auto& r : summary) ops.push_back(r.op);
  std::vector<std::uint8_t> expected = {0x03, 0x04, 0x04, 0x0B};
  expected.insert(expected.end(), std::size_t(chunks), 0x08);
  CHECK(ops == expected);
  Cursor st{b, summary[3].content};
  CHECK(st.u(8) == 30);  // messages
  CHECK(st.u(2) == 1);   // schemas
  CHECK(st.u(4) == 2);   // channels
  st.u(4);
  st.u(4);
  CHECK(st.u(4) == std::uint64_t(chunks));
  CHECK(st.u(8) == 0);
  CHECK(st.u(8) == 29000);
  // Chunk indexes point at the chunks and their message indexes.
  for (std::size_t i = 4; i < summary.size(); ++i) {
    Cursor ci{b, summary[i].content};
    ci.u(8);
    ci.u(8);
    const auto at = ci.u(8), len = ci.u(8);
    REQUIRE(chunk_at.count(at) == 1);
    CHECK(b[at] == 0x06);
    CHECK(b.at(at + len) == 0x07);  // the first message index right after the chunk
    const auto map_len = ci.u(4);
    for (std::uint64_t e = 0; e < map_len / 10; ++e) {
      ci.u(2);
      CHECK(b.at(ci.u(8)) == 0x07);
    }
  }
  // Summary offsets: one per group, pointing at its first record.
  const auto offsets = records(b, offsets_start, b.size() - 8 - 29);
  CHECK(offsets.size() == 4);
  for (const auto& o : offsets) {
    Cursor so{b, o.content};
    const auto op = so.u(1), start = so.u(8);
    CHECK(b.at(start) == op);
  }
  std::filesystem::remove(path);
}

TEST_CASE("BagWriter: no heap allocation per sample once running", "[ros2][mcap]") {
  const std::filesystem::path path = "test_ros2_bag_alloc.mcap";
  r2::BagWriter bag(path);
  kelp::vehicle::VehicleStated boat, rov;
  Eigen::Matrix<double, 3, Eigen::Dynamic> nodes =
      Eigen::Matrix<double, 3, Eigen::Dynamic>::Zero(3, 41);
  Eigen::VectorXd tensions = Eigen::VectorXd::Constant(40, 10.0);
  r2::RunSample s;
  s.boat = &boat;
  s.rov = &rov;
  s.nodes = &nodes;
  s.tensions = &tensions;
  r2::Messages m;
  // Warm up: the first chunks size every buffer.
  int k = 0;
  for (; k < 3000; ++k) {
    s.time = 0.1 * k;
    r2::fill_messages(s, m);
    bag.write(m);
  }
  const long before = kelp_test::allocations;
  for (; k < 3100; ++k) {
    s.time = 0.1 * k;
    r2::fill_messages(s, m);
    bag.write(m, k % 10 == 0);
  }
  // Only a chunk index entry a flushed chunk may allocate (a few per 100 samples at most).
  CHECK(kelp_test::allocations - before <= 8);
  bag.close();
  std::filesystem::remove(path);
}

TEST_CASE("McapWriter: an unwritable path is a kelp::error", "[ros2][mcap]") {
  CHECK_THROWS_AS(r2::McapWriter("/nonexistent-dir/x/run.mcap"), kelp::error);
  r2::McapWriter w;
  CHECK_THROWS_AS(w.write(1, 0, 0, nullptr, 0), kelp::invalid_argument);
}

TEST_CASE("McapWriter: each completed chunk and its indexes reach the file at once",
          "[ros2][mcap][stop]") {
  // What a run killed mid-way leaves (kelp/sim/stop.hpp): every completed chunk with its message
  // indexes on the file, not in the stdio buffer (@mcap/core's stream reader reads it: the
  // check of apps/tethered_pair/check_stop.py).
  const std::filesystem::path path = "test_ros2_mcap_chunk_flush.mcap";
  r2::McapOptions opt;
  opt.chunk_size = 4096;
  r2::McapWriter w(path, opt);
  const std::uint16_t schema = w.add_schema("std_msgs/msg/Empty", "ros2msg", "");
  const std::uint16_t channel = w.add_channel(schema, "/a", "cdr");
  const std::uint8_t payload[100] = {};
  int chunks = 0;
  for (std::uint32_t i = 0; i < 400; ++i) {
    const std::uint64_t before = w.bytes_written();
    w.write(channel, i, 1000u * i, payload, sizeof payload);
    if (w.bytes_written() != before) {  // a chunk was completed: all of it is on the file
      ++chunks;
      CHECK(std::filesystem::file_size(path) == w.bytes_written());
    }
  }
  CHECK(chunks >= 5);
  w.close();
  std::filesystem::remove(path);
}
