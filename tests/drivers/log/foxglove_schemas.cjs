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
// --tracks FILE: FILE holds the tracks lines `fusedet replay --tracks` wrote for the same raw log
//   (what the socket's tracks stream sends); each stack's /tracks message must carry the same
//   tracks and its /tracks/scene entities must draw exactly them: entity id track-N and metadata,
//   the sphere at the track's position in laser_base, the arrow along its velocity (the quaternion
//   applied to +x here), the state by colour, a lifetime, the previous entities deleted.
// Usage: node foxglove_schemas.cjs NODE_PREFIX LOG.mcap [--schemas-only | --tracks FILE]
"use strict";
const fs = require("fs");
const path = require("path");
const [prefix, logPath, mode, tracksPath] = process.argv.slice(2);
const schemasOnly = mode === "--schemas-only";
const replayTracks = mode === "--tracks" ? fs.readFileSync(tracksPath, "utf8").split("\n").filter((l) => l).map((l) => JSON.parse(l)) : null;
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
  const trackLines = [], scenes = [];
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
    if (ch.topic === "/tracks") trackLines.push({ t: m.logTime, j });
    if (ch.topic === "/tracks/scene") scenes.push({ t: m.logTime, j });
    if (schema === "foxglove.ImageAnnotations") {
      annotationStamps.push(stamp);
      boxes += j.points.length;
      check(j.points.length === j.texts.length, "one label per box");
    }
  }
  for (const [k, n] of Object.entries(bad)) check(false, `${n} invalid messages on ${k}`);
  for (const [t, n] of Object.entries(counts).sort()) console.log(`count ${t} ${n}`);
  if (!schemasOnly) derivedChecks();
  if (replayTracks) trackChecks();
  console.log(`@foxglove/schemas validated ${Object.values(counts).reduce((a, b) => a + b, 0)} messages on ${reader.channelsById.size} channels; ${boxes} detection boxes`);
  if (failures) {
    console.log(`${failures} check(s) failed`);
    process.exit(1);
  }
  console.log("foxglove_schemas: OK");

  function derivedChecks() {
  const want = { "/camera/image": "foxglove.RawImage", "/lms291/scan": "foxglove.LaserScan", "/sweep/points": "foxglove.PointCloud",
                 "/detections": "foxglove.ImageAnnotations", "/tf": "foxglove.FrameTransform",
                 "/camera/calibration": "foxglove.CameraCalibration", "/lms291/raw": "fusedet.RawSerial", "/tilt/can": "fusedet.CanFrame",
                 "/tracks": "fusedet.Tracks", "/tracks/scene": "foxglove.SceneUpdate" };
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

  function trackChecks() {
    const ns = (t) => BigInt(t.sec) * 1000000000n + BigInt(t.nsec);
    const near = (a, b, tol) => Math.abs(a - b) <= tol;
    // A quaternion applied to a vector: v' = v + 2 w (q x v) + 2 q x (q x v).
    const rotate = (q, v) => {
      const cross = (a, b) => [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
      const u = [q.x, q.y, q.z], t = cross(u, v).map((c) => 2 * c), ut = cross(u, t);
      return [0, 1, 2].map((i) => v[i] + q.w * t[i] + ut[i]);
    };
    check(trackLines.length === replayTracks.length && scenes.length === replayTracks.length,
          `tracks messages ${trackLines.length} / scenes ${scenes.length} != ${replayTracks.length} stacks of fusedet replay`);
    const states = { confirmed: 0, coasting: 0, tentative: 0 }, ids = new Set(), alphaOf = {};
    let arrows = 0;
    for (let k = 0; k < Math.min(scenes.length, replayTracks.length, trackLines.length); k++) {
      const want = replayTracks[k], line = trackLines[k].j, scene = scenes[k].j, at = `stack ${want.stack}`;
      check(BigInt(want.frame_ns) === trackLines[k].t && BigInt(want.frame_ns) === scenes[k].t, `${at}: log time != the replay's frame_ns`);
      // /tracks carries the socket's line (detected_ns is when this run detected it).
      const strip = (x) => JSON.stringify({ ...x, detected_ns: 0, timestamp: undefined });
      check(strip(line) === strip(want), `${at}: /tracks differs from the replay's tracks line`);
      check(scene.deletions.length === 1 && scene.deletions[0].type === 1 && ns(scene.deletions[0].timestamp) === trackLines[k].t,
            `${at}: the scene does not first delete every earlier entity`);
      const byId = new Map(scene.entities.map((e) => [e.id, e]));
      check(byId.size === want.tracks.length && scene.entities.length === want.tracks.length,
            `${at}: ${scene.entities.length} entities for ${want.tracks.length} tracks`);
      for (const t of want.tracks) {
        const e = byId.get(`track-${t.id}`);
        if (!e) {
          check(false, `${at}: no entity track-${t.id}`);
          continue;
        }
        ids.add(t.id);
        const meta = Object.fromEntries(e.metadata.map((kv) => [kv.key, kv.value]));
        const state = !t.confirmed ? "tentative" : t.coasting ? "coasting" : "confirmed";
        states[state]++;
        check(e.frame_id === "laser_base" && ns(e.timestamp) === scenes[k].t, `${at} track ${t.id}: frame ${e.frame_id} or stamp`);
        check(meta.id === String(t.id) && meta.class === t.class && meta.state === state, `${at} track ${t.id}: metadata ${JSON.stringify(meta)}`);
        check(e.texts.length === 1 && e.texts[0].text.startsWith(`${t.class} ${t.id}`), `${at} track ${t.id}: text`);
        const v = meta.velocity.split(" ").map(Number);
        check(v.length === 3 && v.every((x, i) => near(x, t.velocity[i], 6e-4)), `${at} track ${t.id}: metadata velocity ${meta.velocity} vs ${t.velocity}`);
        const p = e.spheres[0].pose.position;
        check(e.spheres.length === 1 && near(p.x, t.robot[0], 1e-9) && near(p.y, t.robot[1], 1e-9) && near(p.z, t.robot[2], 1e-9),
              `${at} track ${t.id}: sphere at ${JSON.stringify(p)}, track at ${t.robot}`);
        const lifetime = e.lifetime.sec + e.lifetime.nsec * 1e-9;
        check(near(lifetime, 3.0, 1e-9), `${at} track ${t.id}: lifetime ${lifetime} s, want tracking.max_coast_s (3 s)`);
        const speed = Math.hypot(...t.velocity);
        if (speed >= 0.05) {
          arrows++;
          const a = e.arrows[0], dir = a ? rotate(a.pose.orientation, [1, 0, 0]) : [0, 0, 0];
          check(e.arrows.length === 1 && dir.every((d, i) => near(d, t.velocity[i] / speed, 1e-6)) && near(a.shaft_length, speed, 1e-9),
                `${at} track ${t.id}: arrow ${dir} vs velocity ${t.velocity}`);
        } else {
          check(e.arrows.length === 0, `${at} track ${t.id}: an arrow for a standing track`);
        }
        const c = e.spheres[0].color;
        (alphaOf[state] = alphaOf[state] || new Set()).add(`${c.r},${c.g},${c.b},${c.a}` + (state === "tentative" ? "" : `/${t.class}`));
      }
    }
    // The three states look different: tentative grey, coasting translucent, confirmed opaque.
    const colours = (s) => [...(alphaOf[s] || [])];
    check(colours("tentative").every((c) => c.startsWith("0.6,0.6,0.6,")), "tentative tracks are grey");
    check(colours("coasting").every((c) => c.split(",")[3].startsWith("0.3")), "coasting tracks are translucent");
    check(colours("confirmed").every((c) => c.split(",")[3].startsWith("1/")), "confirmed tracks are opaque");
    console.log(`tracks agree with fusedet replay: ${scenes.length} stacks, ${ids.size} track ids, ` +
                `${states.confirmed} confirmed, ${states.coasting} coasting, ${states.tentative} tentative entities, ${arrows} arrows`);
  }
})().catch((e) => {
  console.log("FAIL exception: " + (e && e.stack ? e.stack : e));
  process.exit(1);
});
