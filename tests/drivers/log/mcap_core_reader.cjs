// SPDX-License-Identifier: Apache-2.0
// Independent reader check: @mcap/core (Foxglove's TypeScript MCAP library, from npm) reads a
// fusedet log twice - sequentially (McapStreamReader, chunk CRCs validated) and through the
// summary and indexes (McapIndexedReader) - and compares channels, counts and contents with
// what the writer says it wrote (EXPECTED.json, printed by sample_log_writer).
// Usage: node mcap_core_reader.cjs NODE_PREFIX LOG.mcap EXPECTED.json
"use strict";
const fs = require("fs");
const path = require("path");
const [prefix, logPath, expectedPath] = process.argv.slice(2);
const { McapStreamReader, McapIndexedReader } = require(path.join(prefix, "node_modules", "@mcap/core"));
const fzstd = require(path.join(prefix, "node_modules", "fzstd"));

const expected = JSON.parse(fs.readFileSync(expectedPath, "utf8"));
const bytes = new Uint8Array(fs.readFileSync(logPath));
const decompressHandlers = { zstd: (buf, size) => fzstd.decompress(buf, new Uint8Array(Number(size))) };
let failures = 0;
function check(cond, what) {
  if (!cond) {
    failures++;
    console.log("FAIL " + what);
  }
}
const text = (data) => JSON.parse(Buffer.from(data).toString("utf8"));

// 1. Sequential read with CRC validation.
const stream = new McapStreamReader({ decompressHandlers, validateCrcs: true });
stream.append(bytes);
const topics = new Map(), schemas = new Map(), streamCounts = {};
const kinds = {};
let rec, second = null, metadata = null, lastTime = -1n, ordered = true;
while ((rec = stream.nextRecord())) {
  kinds[rec.type] = (kinds[rec.type] || 0) + 1;
  if (rec.type === "Schema") schemas.set(rec.id, rec.name);
  if (rec.type === "Channel") topics.set(rec.id, { topic: rec.topic, schema: schemas.get(rec.schemaId), enc: rec.messageEncoding });
  if (rec.type === "Metadata" && rec.name === "fusedet.config") metadata = rec.metadata;
  if (rec.type === "Message") {
    const t = topics.get(rec.channelId).topic;
    streamCounts[t] = (streamCounts[t] || 0) + 1;
    if (t === "/lms291/raw" && rec.sequence === 1) second = text(rec.data);
  }
}
check(stream.done(), "stream reader reached the end magic");
console.log("stream reader records: " + JSON.stringify(kinds));
for (const [t, n] of Object.entries(expected.counts)) check(streamCounts[t] === n, `stream count ${t}: ${streamCounts[t]} != ${n}`);
for (const [id, c] of topics) {
  check(c.enc === "json", `${c.topic} message encoding ${c.enc}`);
  if (expected.schemas[c.topic]) check(c.schema === expected.schemas[c.topic], `${c.topic} schema ${c.schema}`);
}
check(second && second.data === expected.second_serial_base64, "second serial chunk bytes: " + JSON.stringify(second));
check(second && second.baud === 500000 && second.device === "/dev/ttyUSB0", "serial chunk fields");
check(metadata && metadata.get("config.yaml") === expected.config_yaml, "fusedet.config metadata config.yaml");

// 2. Indexed read through the summary, chunk indexes and message indexes.
(async () => {
  const readable = {
    size: async () => BigInt(bytes.length),
    read: async (offset, size) => bytes.subarray(Number(offset), Number(offset + size)),
  };
  const reader = await McapIndexedReader.Initialize({ readable, decompressHandlers });
  const stats = reader.statistics;
  check(stats && Number(stats.messageCount) === expected.total, `statistics messageCount ${stats && stats.messageCount} != ${expected.total}`);
  check(stats && stats.messageStartTime === BigInt(expected.first_time_ns), "statistics start time");
  check(reader.chunkIndexes.length > 1, "several chunks indexed: " + reader.chunkIndexes.length);
  const indexedCounts = {};
  let scanSeen = 0, imageOk = false;
  for await (const m of reader.readMessages()) {
    if (m.logTime < lastTime) ordered = false;
    lastTime = m.logTime;
    const t = reader.channelsById.get(m.channelId).topic;
    indexedCounts[t] = (indexedCounts[t] || 0) + 1;
    if (t === "/lms291/scan" && scanSeen++ === 3) check(text(m.data).ranges.length === 101 && text(m.data).ranges[0] === 5.5, "4th scan ranges");
    if (t === "/camera/image" && !imageOk) {
      const j = text(m.data);
      imageOk = j.encoding === "yuyv" && j.width === 8 && j.height === 2 && Buffer.from(j.data, "base64").length === 32;
    }
  }
  check(ordered, "indexed reader yields messages in log-time order");
  check(imageOk, "first camera image: yuyv 8x2, 32 bytes");
  for (const [t, n] of Object.entries(expected.counts)) check(indexedCounts[t] === n, `indexed count ${t}: ${indexedCounts[t]} != ${n}`);
  let metaCount = 0;
  for await (const md of reader.readMetadata({ name: "fusedet.config" })) metaCount += md.metadata.get("config.yaml") === expected.config_yaml;
  check(metaCount === 1, "indexed metadata read");
  console.log(`@mcap/core read ${Object.values(indexedCounts).reduce((a, b) => a + b, 0)} messages on ${reader.channelsById.size} channels in ${reader.chunkIndexes.length} chunks`);
  if (failures) {
    console.log(`${failures} check(s) failed`);
    process.exit(1);
  }
  console.log("mcap_core_reader: OK");
})().catch((e) => {
  console.log("FAIL exception: " + (e && e.stack ? e.stack : e));
  process.exit(1);
});
