// SPDX-License-Identifier: Apache-2.0
// Independent check of a derived log against Foxglove's own published schema definitions: the JSON
// Schemas of @foxglove/schemas (npm, the package Foxglove generates from its schema sources),
// validated with Ajv. @mcap/core reads the file through its summary and indexes.
//  - every message on a channel whose schema is foxglove.X validates against Foxglove's X (all
//    fields Foxglove requires, types, enums such as NumericType and PointsAnnotationType);
//  - every message on our own fusedet.* channels validates against the JSON Schema the file
//    carries for it (the documented schemas describe what is written);
//  - frame ids and encodings a viewer needs: camera image yuyv in frame camera, step and data
//    size; scans in laser; sweeps in laser_base with x y z remission float32; transforms
//    laser_base -> laser and laser_base -> camera; calibration in camera; annotations stamped
//    like a camera image (Foxglove draws them on the image with the same stamp).
// Prints "count TOPIC N" per topic for the calling script to compare with fusedet's own reader.
// --schemas-only: only the validation (a log with every channel kind but no derived content).
// Usage: node foxglove_schemas.cjs NODE_PREFIX LOG.mcap [--schemas-only]
"use strict";
const fs = require("fs");
const path = require("path");
const [prefix, logPath, mode] = process.argv.slice(2);
const schemasOnly = mode === "--schemas-only";
const mod = (name) => require(path.join(prefix, "node_modules", name));
const { McapIndexedReader } = mod("@mcap/core");
const fzstd = mod("fzstd");
const Ajv = mod("ajv");
const foxglove = mod("@foxglove/schemas/jsonschema");

let failures = 0;
function check(cond, what) {
  if (!cond) {
    failures++;
    console.log("FAIL " + what);
  }
}
const ajv = new Ajv({ strict: false, allErrors: true });
const validators = new Map();
function foxgloveValidator(name) {
  const short = name.slice("foxglove.".length);
  if (!validators.has(name)) validators.set(name, foxglove[short] ? ajv.compile(foxglove[short]) : null);
  return validators.get(name);
}

(async () => {
  const bytes = new Uint8Array(fs.readFileSync(logPath));
  const readable = { size: async () => BigInt(bytes.length), read: async (o, n) => bytes.subarray(Number(o), Number(o + n)) };
  const decompressHandlers = { zstd: (buf, size) => fzstd.decompress(buf, new Uint8Array(Number(size))) };
  const reader = await McapIndexedReader.Initialize({ readable, decompressHandlers });
  const ownValidators = new Map();
  for (const [id, s] of reader.schemasById) {
    check(s.encoding === "jsonschema", `${s.name}: schema encoding ${s.encoding}`);
    let parsed = null;
    try {
      parsed = JSON.parse(Buffer.from(s.data).toString("utf8"));
    } catch (e) {
      check(false, `${s.name}: schema record is not JSON`);
    }
    if (parsed) {
      check(parsed.title === s.name, `${s.name}: schema title ${parsed.title}`);
      ownValidators.set(id, ajv.compile(parsed));
    }
    if (s.name.startsWith("foxglove.")) check(foxgloveValidator(s.name), `${s.name} is not in @foxglove/schemas`);
  }
  const counts = {}, bad = {}, frames = {}, encodings = new Set(), tfPairs = new Set(), imageStamps = new Set(), annotationStamps = [];
  let imageSizeOk = true, cloudOk = true, calibOk = true, boxes = 0;
  for await (const m of reader.readMessages()) {
    const ch = reader.channelsById.get(m.channelId);
    const schema = reader.schemasById.get(ch.schemaId).name;
    counts[ch.topic] = (counts[ch.topic] || 0) + 1;
    check(ch.messageEncoding === "json", `${ch.topic}: message encoding ${ch.messageEncoding}`);
    const j = JSON.parse(Buffer.from(m.data).toString("utf8"));
    const key = `${ch.topic} (${schema})`;
    const validate = schema.startsWith("foxglove.") ? foxgloveValidator(schema) : ownValidators.get(ch.schemaId);
    if (validate && !validate(j)) {
      if (!bad[key]) console.log(`invalid ${key}: ${ajv.errorsText(validate.errors)}`);
      bad[key] = (bad[key] || 0) + 1;
    }
    if (!ownValidators.get(ch.schemaId)(j)) bad[key + " vs its own schema record"] = (bad[key + " vs its own schema record"] || 0) + 1;
    const stamp = j.timestamp ? BigInt(j.timestamp.sec) * 1000000000n + BigInt(j.timestamp.nsec) : null;
    if (stamp !== null) check(stamp === m.logTime, `${ch.topic}: log time ${m.logTime} != message timestamp ${stamp}`);
    if (j.frame_id !== undefined) (frames[ch.topic] = frames[ch.topic] || new Set()).add(j.frame_id);
    if (schema === "foxglove.RawImage") {
      encodings.add(j.encoding);
      imageStamps.add(stamp);
      imageSizeOk &&= j.step === 2 * j.width && Buffer.from(j.data, "base64").length === j.step * j.height;
    }
    if (schema === "foxglove.PointCloud") {
      const names = j.fields.map((f) => `${f.name}@${f.offset}:${f.type}`).join(" ");
      cloudOk &&= j.point_stride === 16 && names === "x@0:7 y@4:7 z@8:7 remission@12:7" &&
        Buffer.from(j.data, "base64").length % 16 === 0 && Buffer.from(j.data, "base64").length > 16 * 1000;
    }
    if (schema === "foxglove.FrameTransform") tfPairs.add(`${j.parent_frame_id}->${j.child_frame_id}`);
    if (schema === "foxglove.CameraCalibration") calibOk &&= j.K.length === 9 && j.P.length === 12 && j.K[8] === 1 && j.width > 0;
    if (schema === "foxglove.ImageAnnotations") {
      annotationStamps.push(stamp);
      boxes += j.points.length;
      check(j.points.length === j.texts.length, "one label per box");
    }
  }
  for (const [k, n] of Object.entries(bad)) check(false, `${n} invalid messages on ${k}`);
  for (const [t, n] of Object.entries(counts).sort()) console.log(`count ${t} ${n}`);
  if (!schemasOnly) derivedChecks();
  console.log(`@foxglove/schemas validated ${Object.values(counts).reduce((a, b) => a + b, 0)} messages on ${reader.channelsById.size} channels; ${boxes} detection boxes`);
  if (failures) {
    console.log(`${failures} check(s) failed`);
    process.exit(1);
  }
  console.log("foxglove_schemas: OK");

  function derivedChecks() {
  const want = { "/camera/image": "foxglove.RawImage", "/lms291/scan": "foxglove.LaserScan", "/sweep/points": "foxglove.PointCloud",
                 "/detections": "foxglove.ImageAnnotations", "/tf": "foxglove.FrameTransform",
                 "/camera/calibration": "foxglove.CameraCalibration", "/lms291/raw": "fusedet.RawSerial", "/tilt/can": "fusedet.CanFrame" };
  const topicSchema = {};
  for (const ch of reader.channelsById.values()) topicSchema[ch.topic] = reader.schemasById.get(ch.schemaId).name;
  for (const [t, s] of Object.entries(want)) check(topicSchema[t] === s && counts[t] > 0, `${t}: ${topicSchema[t]} with ${counts[t]} messages, want ${s}`);
  const only = (t, id) => check(frames[t] && frames[t].size === 1 && frames[t].has(id), `${t} frame ids ${frames[t] && [...frames[t]]} != ${id}`);
  only("/camera/image", "camera");
  only("/lms291/scan", "laser");
  only("/sweep/points", "laser_base");
  only("/camera/calibration", "camera");
  check(encodings.size === 1 && encodings.has("yuyv"), "camera encoding yuyv: " + [...encodings]);
  check(imageSizeOk, "every image: step = 2 x width, data = step x height bytes");
  check(cloudOk, "every point cloud: stride 16, x y z remission float32, > 1000 points");
  check(calibOk, "calibration K 3x3, P 3x4");
  check(tfPairs.has("laser_base->laser") && tfPairs.has("laser_base->camera"), "transforms: " + [...tfPairs]);
  check(annotationStamps.length > 0 && annotationStamps.every((t) => imageStamps.has(t)), "every annotation stamped like a camera image");
  }
})().catch((e) => {
  console.log("FAIL exception: " + (e && e.stack ? e.stack : e));
  process.exit(1);
});
