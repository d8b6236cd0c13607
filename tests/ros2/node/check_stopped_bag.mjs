// What a stopped or killed run leaves in run.mcap, read by the official MCAP library (@mcap/core;
// run by apps/tethered_pair/check_stop.py, CTest: example_tethered_pair_stop).
//
//   node check_stopped_bag.mjs closed FILE   a run stopped by SIGINT / SIGTERM: the bag was closed
//       whole, so McapIndexedReader opens it (footer, summary and its CRC, chunk indexes) and
//       reads every message through the index with chunk CRCs validated; the statistics count
//       them, and McapStreamReader reads the same messages front to back to the footer.
//   node check_stopped_bag.mjs killed FILE   a run killed (SIGKILL) mid-way: no summary, no footer.
//       McapStreamReader (CRCs validated) reads it front to back: at least one chunk, and every
//       chunk whole and followed by its message indexes, which index exactly the chunk's
//       messages, and the file ends right after the last chunk's indexes: no byte the reader
//       cannot use (kelp's McapWriter writes each completed chunk and its indexes in one system
//       call, so a process stopped at any instant of its own never leaves part of one; a kill
//       while the kernel copies them could, which the test avoids by stopping the process first).
//
// Prints one JSON line: {"messages": n, "chunks": c, "last_log_time_s": t}. Exit status 1 with
// the reasons on stderr when a check fails.
import { McapIndexedReader, McapStreamReader } from "@mcap/core";
import fs from "node:fs";

const [mode, file] = process.argv.slice(2);
let failures = 0;
function fail(what) {
  failures++;
  console.error(`FAIL ${file}: ${what}`);
}

const buf = fs.readFileSync(file);
const bytes = new Uint8Array(buf.buffer, buf.byteOffset, buf.byteLength);
let messages = 0;
let chunks = 0;
let last = 0n;

if (mode === "closed") {
  const readable = {
    size: async () => BigInt(bytes.byteLength),
    read: async (offset, size) => bytes.subarray(Number(offset), Number(offset + size)),
  };
  const reader = await McapIndexedReader.Initialize({ readable });
  chunks = reader.chunkIndexes.length;
  for await (const m of reader.readMessages({ validateCrcs: true })) {
    messages++;
    if (m.logTime > last) last = m.logTime;
  }
  if (BigInt(messages) !== reader.statistics.messageCount)
    fail(`read ${messages} messages, the statistics say ${reader.statistics.messageCount}`);
  const stream = new McapStreamReader({ validateCrcs: true });
  stream.append(bytes);
  let streamed = 0;
  for (let r; (r = stream.nextRecord()); ) if (r.type === "Message") streamed++;
  if (!stream.done()) fail("the stream reader did not reach the footer");
  if (streamed !== messages) fail(`streamed ${streamed} messages, indexed ${messages}`);
} else if (mode === "killed") {
  const stream = new McapStreamReader({ validateCrcs: true, includeChunks: true });
  stream.append(bytes);
  // The chunk being read: its messages, and the message index entries after it.
  let chunk = null;
  const closeChunk = () => {
    if (chunk && chunk.indexed !== chunk.messages)
      fail(`chunk ${chunks}: ${chunk.messages} messages, ${chunk.indexed} in its message indexes`);
  };
  try {
    for (let r; (r = stream.nextRecord()); ) {
      if (r.type === "Chunk") {
        closeChunk();
        chunk = { messages: 0, indexed: 0 };
        chunks++;
      } else if (r.type === "Message") {
        if (!chunk || chunk.indexed > 0) fail("a message outside a chunk");
        else chunk.messages++;
        messages++;
        if (r.logTime > last) last = r.logTime;
      } else if (r.type === "MessageIndex") {
        if (!chunk) fail("a message index before any chunk");
        else chunk.indexed += r.records.length;
      } else if (r.type === "Footer" || r.type === "DataEnd") {
        fail(`a ${r.type} record: the bag was closed, not killed`);
      }
    }
  } catch (e) {
    fail(`the stream reader failed: ${e.message}`);
  }
  closeChunk();
  if (stream.done()) fail("the stream reader reached a footer: the bag was closed, not killed");
  if (chunks === 0) fail("no complete chunk");
  const rest = stream.bytesRemaining();
  if (rest > 0)
    fail(`the file ends in a cut record (opcode 0x${bytes[bytes.byteLength - rest].toString(16)}, ${rest} bytes of it)`);
} else {
  console.error("usage: node check_stopped_bag.mjs closed|killed FILE");
  process.exit(2);
}
if (messages === 0) fail("no message");
console.log(JSON.stringify({ messages, chunks, last_log_time_s: Number(last) / 1e9 }));
process.exit(failures > 0 ? 1 : 0);
