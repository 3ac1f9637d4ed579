// SPDX-License-Identifier: Apache-2.0
// fusedetd's live page: a Foxglove WebSocket protocol client (subprotocol foxglove.websocket.v1,
// JSON-encoded channels) in plain JavaScript, no build step. Subscribes to the camera image, its
// detections, the sweep and the detections' 3D boxes; draws the newest stack whose image and
// detections both arrived (same timestamp), and the sweep from above.
// ?ws=ws://HOST:PORT/ connects elsewhere than the page's own server.
// window.fusedetLive holds what was drawn (tests read it).
"use strict";

const WANTED = ["/camera/compressed", "/detections", "/sweep/points", "/detections/scene"];
const state = (window.fusedetLive = {
  connected: false, channels: [], messages: 0, stacksDrawn: 0, sweepsDrawn: 0,
  drawn: null,  // {stampNs, width, height, boxes: [{x, y, w, h, label, colour}]}
  sweepPoints: 0, errors: [],
});
const stateText = document.getElementById("state");
const imageCanvas = document.getElementById("image");
const sweepCanvas = document.getElementById("sweep");
const decoder = new TextDecoder();
const byStamp = new Map();  // stamp (string, ns) -> {image, annotations}
let sweep = null, scene = null;

function connect() {
  const param = new URLSearchParams(location.search).get("ws");
  const url = param || (location.protocol === "https:" ? "wss://" : "ws://") + location.host + "/";
  const ws = new WebSocket(url, "foxglove.websocket.v1");
  ws.binaryType = "arraybuffer";
  const topicOf = new Map();  // subscription id -> topic
  ws.onopen = () => { state.connected = true; stateText.textContent = "connected to " + url; };
  ws.onclose = () => {
    state.connected = false;
    stateText.textContent = "disconnected; retrying in 2 s";
    setTimeout(connect, 2000);
  };
  ws.onmessage = (event) => {
    if (typeof event.data === "string") {
      const m = JSON.parse(event.data);
      if (m.op === "advertise") {
        const subscriptions = [];
        for (const c of m.channels) {
          state.channels.push(c.topic);
          if (WANTED.includes(c.topic)) {
            const id = subscriptions.length + 1;
            topicOf.set(id, c.topic);
            subscriptions.push({ id, channelId: c.id });
          }
        }
        ws.send(JSON.stringify({ op: "subscribe", subscriptions }));
      } else if (m.op === "status") {
        state.errors.push(m.message);
      }
      return;
    }
    const view = new DataView(event.data);
    if (view.getUint8(0) !== 1) return;  // Message Data only
    const topic = topicOf.get(view.getUint32(1, true));
    const stamp = view.getBigUint64(5, true).toString();
    const message = JSON.parse(decoder.decode(new Uint8Array(event.data, 13)));
    state.messages++;
    onMessage(topic, stamp, message);
  };
}

function onMessage(topic, stamp, m) {
  if (topic === "/sweep/points") { sweep = m; drawSweep(); return; }
  if (topic === "/detections/scene") { scene = m; drawSweep(); return; }
  const entry = byStamp.get(stamp) || {};
  if (topic === "/camera/compressed") entry.image = m;
  if (topic === "/detections") entry.annotations = m;
  byStamp.set(stamp, entry);
  if (entry.image && entry.annotations) {
    byStamp.delete(stamp);
    drawStack(stamp, entry.image, entry.annotations);
  }
  while (byStamp.size > 8) byStamp.delete(byStamp.keys().next().value);  // halves that never got their pair
}

function colour(c) {
  return `rgba(${Math.round(c.r * 255)}, ${Math.round(c.g * 255)}, ${Math.round(c.b * 255)}, ${c.a})`;
}

function drawStack(stamp, image, annotations) {
  const img = new Image();
  img.onload = () => {
    imageCanvas.width = img.naturalWidth;
    imageCanvas.height = img.naturalHeight;
    const g = imageCanvas.getContext("2d");
    g.drawImage(img, 0, 0);
    const boxes = [];
    annotations.points.forEach((p, i) => {
      if (p.type !== 2 || p.points.length !== 4) return;  // LINE_LOOP boxes
      const [a, , c] = p.points;
      const box = { x: a.x, y: a.y, w: c.x - a.x, h: c.y - a.y, label: annotations.texts[i] ? annotations.texts[i].text : "",
                    colour: p.outline_color };
      boxes.push(box);
      g.strokeStyle = colour(p.outline_color);
      g.lineWidth = p.thickness || 2;
      g.strokeRect(box.x, box.y, box.w, box.h);
    });
    for (const t of annotations.texts) {
      g.font = `${t.font_size || 14}px sans-serif`;
      const w = g.measureText(t.text).width;
      g.fillStyle = colour(t.background_color);
      g.fillRect(t.position.x, t.position.y - (t.font_size || 14) - 4, w + 6, (t.font_size || 14) + 4);
      g.fillStyle = colour(t.text_color);
      g.fillText(t.text, t.position.x + 3, t.position.y - 4);
    }
    state.drawn = { stampNs: stamp, width: img.naturalWidth, height: img.naturalHeight, boxes };
    state.stacksDrawn++;
    const rows = boxes.map((b) => {
      const [cls, score] = b.label.split(" ");
      return `<tr><td>${cls}</td><td>${score}</td><td>${b.x.toFixed(0)}</td><td>${b.y.toFixed(0)}</td><td>${b.w.toFixed(0)}</td><td>${b.h.toFixed(0)}</td></tr>`;
    });
    document.querySelector("#detections tbody").innerHTML = rows.join("");
    stateText.textContent = `stack at ${stamp} ns: ${boxes.length} detections; ${state.stacksDrawn} stacks drawn`;
  };
  img.src = "data:image/jpeg;base64," + image.data;
}

// Top-down: laser_base x forward (up on the canvas), y left; the scale fits 20 m ahead.
function drawSweep() {
  const g = sweepCanvas.getContext("2d");
  const W = sweepCanvas.width, H = sweepCanvas.height, scale = H / 20;
  const toCanvas = (x, y) => [W / 2 - y * scale, H - 10 - x * scale];
  g.fillStyle = "#000";
  g.fillRect(0, 0, W, H);
  g.strokeStyle = "#333";
  for (let r = 1; r <= 20; r++) {
    const [cx, cy] = toCanvas(0, 0);
    g.beginPath();
    g.arc(cx, cy, r * scale, 0, 2 * Math.PI);
    g.stroke();
  }
  if (sweep) {
    const bytes = Uint8Array.from(atob(sweep.data), (ch) => ch.charCodeAt(0));
    const view = new DataView(bytes.buffer);
    const stride = sweep.point_stride, n = Math.floor(bytes.length / stride);
    for (let i = 0; i < n; i++) {
      const x = view.getFloat32(i * stride, true), y = view.getFloat32(i * stride + 4, true), z = view.getFloat32(i * stride + 8, true);
      const [u, v] = toCanvas(x, y);
      const t = Math.max(0, Math.min(1, (z + 1.5) / 3));  // height -1.5 .. 1.5 m: blue .. red
      g.fillStyle = `rgb(${Math.round(255 * t)}, ${Math.round(120 + 80 * (1 - Math.abs(t - 0.5) * 2))}, ${Math.round(255 * (1 - t))})`;
      g.fillRect(u, v, 1.5, 1.5);
    }
    state.sweepPoints = n;
    state.sweepsDrawn++;
  }
  if (scene) {
    for (const e of scene.entities) {
      for (const c of e.cubes || []) {
        const [u, v] = toCanvas(c.pose.position.x, c.pose.position.y);
        g.strokeStyle = colour({ ...c.color, a: 1 });
        g.lineWidth = 2;
        g.strokeRect(u - (c.size.y * scale) / 2, v - (c.size.x * scale) / 2, c.size.y * scale, c.size.x * scale);
      }
    }
  }
}

connect();
