// SPDX-License-Identifier: Apache-2.0
// The live page (daemon/web/) in a real browser: Debian's chromium, headless, driven by
// puppeteer-core, opens http://HOST:PORT/ of a replaying fusedetd. Beside it this script follows
// the detections on fusedetd's Unix socket (the NDJSON protocol, docs/protocol.md). Checks:
//  - the page connects, draws the camera image of a stack with boxes and the sweep from above;
//  - the boxes it drew are that stack's detections as the socket sent them (same frame_ns:
//    class, box within 0.5 px, same count);
//  - the canvas shows them: the pixels under each box's four edges have the box colour;
//  - the sweep view drew points (non-black pixels) and the page logged no errors.
// SCREENSHOT (optional): a PNG of the page.
// Usage: node page_test.cjs NODE_PREFIX HOST:PORT SOCKET PROFILE_DIR [SCREENSHOT]
"use strict";
const path = require("path");
const net = require("net");
const fs = require("fs");
const [prefix, hostPort, socketPath, profile, screenshot] = process.argv.slice(2);
const puppeteer = require(path.join(prefix, "node_modules", "puppeteer-core"));

let failures = 0;
function check(cond, what) {
  if (!cond) {
    failures++;
    console.log("FAIL " + what);
  }
}

// Detection lines from the socket, by frame_ns.
const socketDetections = new Map();
function followSocket() {
  const s = net.createConnection(socketPath, () => s.write(JSON.stringify({ cmd: "subscribe" }) + "\n"));
  let buffer = "";
  s.on("data", (d) => {
    buffer += d;
    let nl;
    while ((nl = buffer.indexOf("\n")) >= 0) {
      const line = buffer.slice(0, nl);
      buffer = buffer.slice(nl + 1);
      const m = JSON.parse(line);
      const frame = /"frame_ns":(\d+)/.exec(line);  // exact: nanosecond stamps exceed a double's integers
      if (m.type === "detections" && frame) socketDetections.set(frame[1], m.detections);
    }
  });
  return s;
}

(async () => {
  const socket = followSocket();
  fs.rmSync(profile, { recursive: true, force: true });
  const browser = await puppeteer.launch({
    executablePath: "/usr/bin/chromium",
    headless: true,
    userDataDir: profile,
    args: ["--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run", "--disable-background-networking",
           "--disable-component-update", "--disable-sync"],
  });
  console.log(`browser ${await browser.version()}`);
  const page = await browser.newPage();
  const pageErrors = [];
  page.on("pageerror", (e) => pageErrors.push(String(e)));
  page.on("console", (m) => { if (m.type() === "error") pageErrors.push(m.text()); });
  await page.setViewport({ width: 1320, height: 900 });
  await page.goto(`http://${hostPort}/`, { waitUntil: "load" });
  // A drawn stack with boxes whose socket line has arrived too, and a drawn sweep.
  let drawn = null;
  const deadline = Date.now() + 90000;
  while (Date.now() < deadline) {
    const s = await page.evaluate(() => window.fusedetLive);
    if (s.drawn && s.drawn.boxes.length > 0 && s.sweepsDrawn > 0 && socketDetections.has(s.drawn.stampNs)) {
      drawn = s;
      break;
    }
    await new Promise((r) => setTimeout(r, 250));
  }
  check(drawn, "within 90 s the page drew a stack with boxes and a sweep, and the socket sent that stack");
  if (drawn) {
    const d = drawn.drawn;
    const expected = socketDetections.get(d.stampNs);
    console.log(`page drew stack ${d.stampNs}: ${d.width}x${d.height} image, ${d.boxes.length} boxes; the socket sent ${expected.length} detections; ` +
                `${drawn.sweepPoints} sweep points; ${drawn.stacksDrawn} stacks drawn, ${drawn.messages} messages`);
    check(d.boxes.length === expected.length, `box count ${d.boxes.length} = detections ${expected.length}`);
    const used = new Set();
    for (const b of d.boxes) {
      const i = expected.findIndex((e, k) => !used.has(k) && b.label.startsWith(e.class + " ") &&
        Math.abs(e.box[0] - b.x) <= 0.5 && Math.abs(e.box[1] - b.y) <= 0.5 && Math.abs(e.box[2] - b.w) <= 0.5 && Math.abs(e.box[3] - b.h) <= 0.5);
      check(i >= 0, `drawn box ${b.label} [${b.x} ${b.y} ${b.w} ${b.h}] is a detection the socket sent`);
      if (i >= 0) used.add(i);
      console.log(`  ${b.label} at [${b.x.toFixed(1)} ${b.y.toFixed(1)} ${b.w.toFixed(1)} ${b.h.toFixed(1)}]` +
                  (i >= 0 ? ` = socket ${expected[i].class} [${expected[i].box.map((v) => v.toFixed(1)).join(" ")}]` : ""));
    }
    // The canvas shows each box: its colour under the middle of each edge (a pixel either side).
    const pixels = await page.evaluate((boxes) => {
      const canvas = document.getElementById("image");
      const g = canvas.getContext("2d");
      const at = (x, y) => Array.from(g.getImageData(Math.round(x), Math.round(y), 1, 1).data);
      return boxes.map((b) => {
        const edges = [[b.x + b.w / 2, b.y], [b.x + b.w / 2, b.y + b.h], [b.x, b.y + b.h / 2], [b.x + b.w, b.y + b.h / 2]];
        return edges.map(([x, y]) => [at(x, y), at(x - 1, y - 1), at(x + 1, y + 1)]);
      });
    }, d.boxes);
    d.boxes.forEach((b, i) => {
      const want = [b.colour.r * 255, b.colour.g * 255, b.colour.b * 255];
      const near = (p) => Math.abs(p[0] - want[0]) <= 40 && Math.abs(p[1] - want[1]) <= 40 && Math.abs(p[2] - want[2]) <= 40;
      const shown = pixels[i].filter((candidates) => candidates.some(near)).length;
      check(shown === 4, `box ${i} (${b.label}): its colour on ${shown} of 4 edges`);
    });
    const sweepLit = await page.evaluate(() => {
      const c = document.getElementById("sweep");
      const data = c.getContext("2d").getImageData(0, 0, c.width, c.height).data;
      let lit = 0;
      for (let i = 0; i < data.length; i += 4) if (data[i] > 60 || data[i + 1] > 140 || data[i + 2] > 60) lit++;
      return lit;
    });
    check(sweepLit > 500, `the sweep view drew points (${sweepLit} bright pixels)`);
    console.log(`canvas: every box edge in its colour; sweep view ${sweepLit} bright pixels`);
  }
  check(pageErrors.length === 0, `no page errors (${pageErrors.join("; ")})`);
  if (screenshot) {
    await page.screenshot({ path: screenshot });
    console.log(`screenshot ${screenshot}`);
  }
  await browser.close();
  socket.destroy();
  if (failures) {
    console.log(`${failures} check(s) failed`);
    process.exit(1);
  }
  console.log("page_test: OK");
  process.exit(0);
})().catch((e) => {
  console.log("FAIL " + (e && e.stack ? e.stack : e));
  process.exit(1);
});
