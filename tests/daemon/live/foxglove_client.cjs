// SPDX-License-Identifier: Apache-2.0
// fusedetd's live view against the official Foxglove WebSocket client (@foxglove/ws-protocol's
// FoxgloveClient over the `ws` package) and Foxglove's published schemas (@foxglove/schemas'
// JSON Schemas, validated with Ajv):
//  - serverInfo arrives; the advertised channels are the documented ones, JSON-encoded, each
//    with a JSON Schema titled by its schema name;
//  - subscribed to every channel, every message received validates (foxglove.* against
//    @foxglove/schemas, fusedet.* against the schema the channel advertised), carries in its
//    "timestamp" the frame header's timestamp, and what a viewer needs is there: a JPEG image,
//    a sweep of x y z remission float32, boxes stamped like an image, laser_base -> camera;
//  - only subscribed channels are encoded: subscribed to /detections and /status alone, the
//    status' live.encoded counts grow for those and stay for the rest;
//  - a viewer that stops reading (slow_viewer.py) is dropped (live.dropped_slow) while this client
//    keeps receiving;
//  - GET / is the page, GET of anything else 404.
// Usage: node foxglove_client.cjs NODE_PREFIX HOST:PORT
"use strict";
const path = require("path");
const http = require("http");
const [prefix, hostPort] = process.argv.slice(2);
const mod = (name) => require(path.join(prefix, "node_modules", name));
const { FoxgloveClient } = mod("@foxglove/ws-protocol");
const { WebSocket } = mod("ws");
const Ajv = mod("ajv");
const foxglove = mod("@foxglove/schemas/jsonschema");
const url = `ws://${hostPort}/`;

let failures = 0;
function check(cond, what) {
  if (!cond) {
    failures++;
    console.log("FAIL " + what);
  }
}
const sleep = (ms) => new Promise((r) => setTimeout(r, ms));
const ajv = new Ajv({ strict: false, allErrors: true });
const expectedTopics = ["/camera/compressed", "/detections", "/detections/scene", "/sweep/points", "/tf", "/camera/calibration",
                        "/tracks/scene", "/tracks", "/layers/distance", "/layers/remission", "/status"];

function get(pathname) {
  return new Promise((resolve, reject) => {
    http.get(`http://${hostPort}${pathname}`, (res) => {
      let body = "";
      res.on("data", (d) => (body += d));
      res.on("end", () => resolve({ status: res.statusCode, type: res.headers["content-type"], body }));
    }).on("error", reject);
  });
}

function connect() {
  return new Promise((resolve, reject) => {
    const client = new FoxgloveClient({ ws: new WebSocket(url, [FoxgloveClient.SUPPORTED_SUBPROTOCOL]) });
    const session = { client, serverInfo: null, channels: null, messages: [], statusEvents: [] };
    client.on("serverInfo", (info) => (session.serverInfo = info));
    client.on("status", (s) => session.statusEvents.push(s));
    client.on("error", (e) => reject(e));
    client.on("advertise", (channels) => {
      session.channels = channels;
      resolve(session);
    });
    client.on("message", (m) => session.messages.push(m));
    setTimeout(() => reject(new Error("no advertise within 10 s")), 10000);
  });
}

(async () => {
  const page = await get("/");
  check(page.status === 200 && /text\/html/.test(page.type) && page.body.includes("live.js"), `GET / gives the page (${page.status})`);
  const js = await get("/live.js");
  check(js.status === 200 && /javascript/.test(js.type) && js.body.includes("foxglove.websocket.v1"), `GET /live.js (${js.status})`);
  check((await get("/etc/passwd")).status === 404, "GET of another path is 404");
  console.log(`http: / ${page.body.length} bytes, /live.js ${js.body.length} bytes, others 404`);

  const a = await connect();
  check(a.serverInfo && a.serverInfo.name === "fusedetd", "serverInfo from fusedetd");
  const topics = a.channels.map((c) => c.topic);
  check(JSON.stringify(topics) === JSON.stringify(expectedTopics), `advertised ${topics.join(" ")}`);
  const byId = new Map(), validators = new Map();
  for (const c of a.channels) {
    byId.set(c.id, c);
    check(c.encoding === "json" && c.schemaEncoding === "jsonschema", `${c.topic}: encoding ${c.encoding}/${c.schemaEncoding}`);
    const schema = JSON.parse(c.schema);
    check(schema.title === c.schemaName, `${c.topic}: schema title ${schema.title} != ${c.schemaName}`);
    if (c.schemaName.startsWith("foxglove.")) {
      const published = foxglove[c.schemaName.slice("foxglove.".length)];
      check(published, `${c.schemaName} is in @foxglove/schemas`);
      validators.set(c.id, ajv.compile(published));
    } else {
      validators.set(c.id, ajv.compile(schema));
    }
  }
  console.log(`listed ${a.channels.length} channels: ${a.channels.map((c) => `${c.topic} (${c.schemaName})`).join(", ")}`);

  // Every channel, until each stack-borne channel had a message (the log loops).
  const subs = new Map();
  for (const c of a.channels) subs.set(a.client.subscribe(c.id), c);
  const seen = () => new Set(a.messages.map((m) => subs.get(m.subscriptionId).topic));
  for (let i = 0; i < 120 && seen().size < expectedTopics.length; i++) await sleep(500);
  await sleep(1500);
  check(seen().size === expectedTopics.length, `messages on every channel (got ${[...seen()].join(" ")})`);
  const counts = {}, invalid = {};
  let images = 0, jpegs = 0, clouds = 0, boxes = 0, annotationStampsMatched = 0, annotations = 0, tf = 0;
  const imageStamps = new Set();
  const decoded = a.messages.map((m) => ({ m, c: subs.get(m.subscriptionId), j: JSON.parse(new TextDecoder().decode(m.data)) }));
  for (const { m, c, j } of decoded) if (c.topic === "/camera/compressed") imageStamps.add(m.timestamp);
  for (const { m, c, j } of decoded) {
    counts[c.topic] = (counts[c.topic] || 0) + 1;
    const validate = validators.get(c.id);
    if (!validate(j)) {
      if (!invalid[c.topic]) console.log(`invalid ${c.topic}: ${ajv.errorsText(validate.errors)}`);
      invalid[c.topic] = (invalid[c.topic] || 0) + 1;
    }
    const stamp = j.timestamp ? BigInt(j.timestamp.sec) * 1000000000n + BigInt(j.timestamp.nsec) : null;
    const first = (j.deletions && j.deletions[0]) || (j.entities && j.entities[0]);
    const sceneStamp = first ? BigInt(first.timestamp.sec) * 1000000000n + BigInt(first.timestamp.nsec) : null;
    check((stamp ?? sceneStamp) === m.timestamp, `${c.topic}: frame timestamp ${m.timestamp} != message timestamp ${stamp ?? sceneStamp}`);
    if (c.schemaName === "foxglove.CompressedImage") {
      const bytes = Buffer.from(j.data, "base64");
      images++;
      if (j.format === "jpeg" && bytes[0] === 0xff && bytes[1] === 0xd8 && j.frame_id === "camera") jpegs++;
    }
    if (c.topic === "/sweep/points") {
      const names = j.fields.map((f) => `${f.name}@${f.offset}:${f.type}`).join(" ");
      if (j.frame_id === "laser_base" && j.point_stride === 16 && names === "x@0:7 y@4:7 z@8:7 remission@12:7" &&
          Buffer.from(j.data, "base64").length > 16 * 1000) clouds++;
    }
    if (c.topic === "/detections") {
      annotations++;
      boxes += j.points.length;
      if (imageStamps.has(m.timestamp)) annotationStampsMatched++;
    }
    if (c.topic === "/tf" && j.parent_frame_id === "laser_base" && j.child_frame_id === "camera") tf++;
  }
  for (const [t, n] of Object.entries(invalid)) check(false, `${n} invalid messages on ${t}`);
  check(jpegs === images && images > 0, `images are JPEG in frame camera (${jpegs} of ${images})`);
  check(clouds === counts["/sweep/points"], `sweeps in laser_base, x y z remission, > 1000 points (${clouds} of ${counts["/sweep/points"]})`);
  check(annotationStampsMatched === annotations, `annotations stamped like an image (${annotationStampsMatched} of ${annotations})`);
  check(tf === counts["/tf"], "transforms laser_base -> camera");
  console.log(`received ${decoded.length} messages: ${Object.entries(counts).map(([t, n]) => `${t} ${n}`).join(", ")}; ${boxes} detection boxes`);
  console.log(`@foxglove/schemas validated ${decoded.length - Object.values(invalid).reduce((x, y) => x + y, 0)} of ${decoded.length} messages on ${Object.keys(counts).length} channels`);

  // Only what is subscribed is encoded.
  for (const id of subs.keys()) a.client.unsubscribe(id);
  const statusChannel = a.channels.find((c) => c.topic === "/status");
  const detections = a.channels.find((c) => c.topic === "/detections");
  const statusSub = a.client.subscribe(statusChannel.id);
  a.client.subscribe(detections.id);
  a.messages.length = 0;
  const statuses = () => a.messages.filter((m) => m.subscriptionId === statusSub).map((m) => JSON.parse(new TextDecoder().decode(m.data)));
  for (let i = 0; i < 40 && statuses().length < 1; i++) await sleep(250);
  const before = statuses()[0];
  await sleep(4000);
  const after = statuses().at(-1);
  const grew = Object.keys(after.live.encoded).filter((t) => after.live.encoded[t] > before.live.encoded[t]).sort();
  check(JSON.stringify(grew) === JSON.stringify(["/detections", "/status"]), `only subscribed channels encoded: grew ${grew.join(" ")}`);
  console.log(`subscribed to /detections and /status only: encoded counts grew for ${grew.join(" ")} ` +
              `(stacks ${before.live.stacks} -> ${after.live.stacks}), the other ${Object.keys(after.live.encoded).length - grew.length} stayed`);

  // A viewer that stops reading (slow_viewer.py: 4 KiB receive buffer) is dropped; this one keeps receiving.
  const slow = require("child_process").spawn("python3", [path.join(__dirname, "slow_viewer.py"), hostPort, "150"], { stdio: ["ignore", "pipe", "inherit"] });
  let slowOut = "";
  slow.stdout.on("data", (d) => (slowOut += d));
  const slowStart = Date.now();
  let dropped = false;
  while (Date.now() - slowStart < 150000) {
    await sleep(500);
    const s = statuses().at(-1);
    if (s && s.live.dropped_slow >= 1) { dropped = true; break; }
  }
  const slowSeconds = (Date.now() - slowStart) / 1000;
  slow.kill();
  const n0 = a.messages.length;
  await sleep(3000);
  const last = statuses().at(-1);
  check(slowOut.startsWith("subscribed "), `the slow viewer subscribed (${slowOut.trim()})`);
  check(dropped, "the viewer that stopped reading was disconnected (live.dropped_slow)");
  check(a.messages.length > n0, "the reading client kept receiving");
  check(last.live.viewers === 1, `one viewer left (${last.live.viewers})`);
  console.log(`slow viewer dropped: ${dropped} (after ${slowSeconds.toFixed(1)} s); live.dropped_slow ${last.live.dropped_slow}; ` +
              `the other client received ${a.messages.length - n0} messages in the 3 s after`);
  a.client.close();
  if (failures) {
    console.log(`${failures} check(s) failed`);
    process.exit(1);
  }
  console.log("foxglove_client: OK");
  process.exit(0);
})().catch((e) => {
  console.log("FAIL " + (e && e.stack ? e.stack : e));
  process.exit(1);
});
