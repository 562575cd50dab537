// mmm station: the operator's page. Talks to the JSON API of `mmm serve`
// (docs/operators.md: "Operator web UI and its JSON API"). A task's request
// says its "kind"; TASK_KINDS (at the end) maps each kind to the class that
// shows it: LandmarkTask (place landmarks in both views) and
// OutlineReviewTask (accept the bones' outlines or click their true edges).
// Both have the same shape: views, mine, place(view, u, v), submission(),
// complete(), preview(), showPreview(reasons, values), refresh(),
// updateButtons(), drawOverlay(view, context), select(index), enter().
//
// Pixel convention (core/image/projection.h): u right, v down; pixel (i, j)
// covers [i, i+1) x [j, j+1), so the image spans [0, width] x [0, height].
// A view shows the image at scale s with offset (ox, oy) in canvas CSS
// pixels: x = ox + u s, y = oy + v s. Window/level maps the 16-bit samples
// to grey on the client, from the full 16-bit data.
"use strict";

(() => {
  const $ = (id) => document.getElementById(id);
  const TOKEN_KEY = "mmm-station-token";
  const COLOURS = ["#ff6b6b", "#ffd166", "#4fd1c5", "#a78bfa", "#f78fb3", "#7bd389"];

  // ---- API ---------------------------------------------------------------
  let token = localStorage.getItem(TOKEN_KEY) || "";
  let operator = "";

  class ApiError extends Error {
    constructor(status, body) {
      super(body && body.error ? body.error : `HTTP ${status}`);
      this.status = status;
      this.hint = body && body.hint ? body.hint : "";
    }
  }

  async function api(method, path, body) {
    const headers = { Authorization: `Bearer ${token}` };
    if (body !== undefined) headers["Content-Type"] = "application/json";
    const response = await fetch(path, {
      method, headers, body: body === undefined ? undefined : JSON.stringify(body),
    });
    if (response.status === 401) {
      showSignIn("Your token was not accepted: " + (await response.json()).error);
      throw new ApiError(401, { error: "not signed in" });
    }
    const type = response.headers.get("Content-Type") || "";
    if (!type.startsWith("application/json")) {
      if (!response.ok) throw new ApiError(response.status, null);
      return response;
    }
    const json = await response.json();
    if (!response.ok) throw new ApiError(response.status, json);
    return json;
  }

  const errorText = (error) => error.message + (error.hint ? ` (${error.hint})` : "");

  // ---- pages -------------------------------------------------------------
  const pages = ["sign-in", "worklist", "task"];
  function showPage(name) {
    for (const page of pages) $(page).hidden = page !== name;
  }

  function showSignIn(message) {
    stopPolling();
    showPage("sign-in");
    $("sign-in-error").textContent = message || "";
    $("whoami").textContent = "";
    $("sign-out").hidden = true;
    $("token").focus();
  }

  $("token-form").addEventListener("submit", async (event) => {
    event.preventDefault();
    token = $("token").value.trim();
    localStorage.setItem(TOKEN_KEY, token);
    $("token").value = "";
    await start();
  });

  $("sign-out").addEventListener("click", () => {
    token = "";
    localStorage.removeItem(TOKEN_KEY);
    showSignIn("");
  });

  async function start() {
    if (!token) return showSignIn("");
    try {
      const me = await api("GET", "/api/whoami");
      operator = me.operator;
      $("whoami").textContent = `${operator} · ${me.root}`;
      $("sign-out").hidden = false;
      route();
    } catch (error) {
      if (error.status !== 401) showSignIn(errorText(error));
    }
  }

  function route() {
    if (!operator) return;
    stopPolling();
    const match = location.hash.match(/^#\/task\/([0-9a-f]+)$/);
    if (match) openTask(match[1]);
    else openWorklist();
  }
  window.addEventListener("hashchange", route);

  // ---- worklist ----------------------------------------------------------
  const chip = (state) => `<span class="chip ${state}">${state}</span>`;
  const escape = (text) => String(text).replace(/[&<>"']/g, (c) => `&#${c.charCodeAt(0)};`);

  async function openWorklist() {
    showPage("worklist");
    const params = new URLSearchParams();
    if ($("only-mine").checked) params.set("assignee", operator);
    if ($("show-closed").checked) params.set("all", "1");
    try {
      const { tasks } = await api("GET", `/api/worklist?${params}`);
      $("task-rows").innerHTML = tasks.map((t) =>
        `<tr data-task="${escape(t.id)}"><td><a href="#/task/${escape(t.id)}">${escape(t.id)}</a></td>` +
        `<td>${escape(t.patient)}</td><td>${escape(t.study)}</td><td>${escape(t.node)}</td>` +
        `<td>${chip(escape(t.state))}</td><td>${escape(t.assignee || "—")}</td><td>${escape(t.age)}</td></tr>`).join("");
      $("worklist-empty").hidden = tasks.length > 0;
    } catch (error) {
      $("task-rows").innerHTML = `<tr><td colspan="7" class="error">${escape(errorText(error))}</td></tr>`;
    }
  }
  $("task-rows").addEventListener("click", (event) => {
    const row = event.target.closest("tr[data-task]");
    if (row) location.hash = `#/task/${row.dataset.task}`;
  });
  for (const id of ["only-mine", "show-closed"]) $(id).addEventListener("change", openWorklist);
  $("refresh").addEventListener("click", openWorklist);

  // ---- geometry ----------------------------------------------------------
  // det of a 3x3 matrix given as rows.
  const det3 = (m) =>
    m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) -
    m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
    m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);

  // Camera centre: the null vector of the 3x4 matrix P (homogeneous 4-vector),
  // C_i = (-1)^i det(P without column i).
  function cameraCentre(P) {
    const centre = [];
    for (let i = 0; i < 4; i++) {
      const minor = P.map((row) => row.filter((_, j) => j !== i));
      centre.push((i % 2 === 0 ? 1 : -1) * det3(minor));
    }
    return centre;
  }

  // P^+ x = P^T (P P^T)^-1 x: a point on the back-projected ray of pixel x.
  function backProject(P, x) {
    const PPt = [0, 1, 2].map((i) => [0, 1, 2].map((j) => P[i].reduce((s, _, k) => s + P[i][k] * P[j][k], 0)));
    const d = det3(PPt);
    const inv = [0, 1, 2].map((i) => [0, 1, 2].map((j) => {
      const rows = [0, 1, 2].filter((r) => r !== j);
      const cols = [0, 1, 2].filter((c) => c !== i);
      const m = rows.map((r) => cols.map((c) => PPt[r][c]));
      return (((i + j) % 2 === 0 ? 1 : -1) * (m[0][0] * m[1][1] - m[0][1] * m[1][0])) / d;
    }));
    const y = inv.map((row) => row[0] * x[0] + row[1] * x[1] + row[2] * x[2]);
    return [0, 1, 2, 3].map((k) => P[0][k] * y[0] + P[1][k] * y[1] + P[2][k] * y[2]);
  }

  const project = (P, X) => P.map((row) => row[0] * X[0] + row[1] * X[1] + row[2] * X[2] + row[3] * X[3]);
  const cross = (a, b) => [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];

  // The epipolar line in view `to` of pixel (u, v) of view `from`, as
  // homogeneous line coefficients (a u + b v + c = 0): the images of the
  // camera centre and of another point of the ray. Pinhole views only.
  function epipolarLine(from, to, u, v) {
    const ray = backProject(from.P, [u, v, 1]);
    return cross(project(to.P, cameraCentre(from.P)), project(to.P, ray));
  }

  // Slot-scanning views (spec.model "slot-scanning", core/image/projection.h):
  // u = h0 / h2 but v = h1, and row v is seen from the focal spot at its own
  // height. The epipolar curve is then sampled along the ray.
  const isSlot = (spec) => spec.model === "slot-scanning";
  const solve3 = (M, b) => {
    const d = det3(M);
    return [0, 1, 2].map((k) => det3(M.map((row, r) => row.map((x, c) => (c === k ? b[r] : x)))) / d);
  };
  function pixelOf(spec, X) {
    const h = project(spec.P, [X[0], X[1], X[2], 1]);
    if (!(h[2] * Math.sign(det3(spec.P.map((row) => row.slice(0, 3)))) > 0)) return null;
    return isSlot(spec) ? [h[0] / h[2], h[1]] : [h[0] / h[2], h[1] / h[2]];
  }
  // Origin (the focal spot) and direction of the ray through pixel (u, v).
  function rayOf(spec, u, v) {
    const M = spec.P.map((row) => row.slice(0, 3));
    const p4 = spec.P.map((row) => -row[3]);
    const source = solve3(M, p4);
    const sign = Math.sign(det3(M));
    if (!isSlot(spec)) return [source, solve3(M, [u, v, 1]).map((x) => sign * x)];
    const travel = solve3(M, [0, 1, 0]);
    return [source.map((s, k) => s + v * travel[k]), solve3(M, [u, 0, 1]).map((x) => sign * x)];
  }
  // The epipolar curve as image points of `to` inside the image, or null.
  function epipolarCurve(from, to, u, v, w, h) {
    if (!isSlot(from) && !isSlot(to)) return clipLine(epipolarLine(from, to, u, v), w, h);
    const [origin, direction] = rayOf(from, u, v);
    const norm = Math.hypot(...direction);
    // Every 5 mm along the first 4 m of the ray (beyond any detector).
    const points = [];
    for (let i = 1; i <= 800; i++) {
      const t = (5 * i) / norm;
      const p = pixelOf(to, origin.map((x, k) => x + t * direction[k]));
      if (p && p[0] >= 0 && p[0] <= w && p[1] >= 0 && p[1] <= h) points.push(p);
    }
    return points.length >= 2 ? points : null;
  }

  // The segment of line l inside [0, w] x [0, h], or null.
  function clipLine(l, w, h) {
    const points = [];
    const add = (u, v) => {
      if (u >= -1e-6 && u <= w + 1e-6 && v >= -1e-6 && v <= h + 1e-6) points.push([u, v]);
    };
    if (Math.abs(l[1]) > 1e-12) { add(0, -l[2] / l[1]); add(w, -(l[0] * w + l[2]) / l[1]); }
    if (Math.abs(l[0]) > 1e-12) { add(-l[2] / l[0], 0); add(-(l[1] * h + l[2]) / l[0], h); }
    if (points.length < 2) return null;
    points.sort((a, b) => a[0] - b[0] || a[1] - b[1]);
    return [points[0], points[points.length - 1]];
  }

  // ---- one radiograph view -------------------------------------------------
  class View {
    constructor(spec, container, station) {
      this.spec = spec;  // name, width, height, P, pixel_spacing_mm
      this.station = station;
      const node = $("view-template").content.firstElementChild.cloneNode(true);
      container.appendChild(node);
      this.node = node;
      this.canvas = node.querySelector("canvas");
      this.canvas.dataset.view = spec.name;
      this.level = node.querySelector(".level");
      this.width = node.querySelector(".width");
      node.querySelector(".view-name").textContent = spec.name;
      node.querySelector(".view-size").textContent =
        `${spec.width} × ${spec.height} px, ${Number(spec.pixel_spacing_mm).toFixed(3)} mm/px`;
      this.scale = 1; this.ox = 0; this.oy = 0;
      this.samples = null;  // Uint16Array
      this.bitmap = document.createElement("canvas");
      this.ready = false;
      this.level.addEventListener("input", () => this.render());
      this.width.addEventListener("input", () => this.render());
      node.querySelector(".auto").addEventListener("click", () => { this.autoWindow(); this.render(); });
      node.querySelector(".fit").addEventListener("click", () => { this.fit(); this.draw(); });
      this.listen();
      new ResizeObserver(() => this.resize()).observe(this.canvas.parentElement);
    }

    async load(taskId) {
      const response = await api("GET", `/api/tasks/${taskId}/views/${encodeURIComponent(this.spec.name)}/pixels`);
      const w = Number(response.headers.get("X-Image-Width"));
      const h = Number(response.headers.get("X-Image-Height"));
      const buffer = await response.arrayBuffer();
      const data = new DataView(buffer);
      this.samples = new Uint16Array(w * h);
      for (let k = 0; k < w * h; k++) this.samples[k] = data.getUint16(2 * k, true);
      this.imageWidth = w; this.imageHeight = h;
      this.bitmap.width = w; this.bitmap.height = h;
      if (this.spec.dicom && this.spec.dicom.window) {
        // The radiograph's own window (DICOM Window Center / Width).
        this.level.value = Math.round(this.spec.dicom.window[0]);
        this.width.value = Math.max(1, Math.round(this.spec.dicom.window[1]));
      } else {
        this.autoWindow();
      }
      this.node.querySelector(".loading").hidden = true;
      this.ready = true;
      this.resize();
      this.fit();
      this.render();
    }

    // Window from the 0.5th to the 99.5th percentile of the samples.
    autoWindow() {
      const histogram = new Uint32Array(65536);
      for (let k = 0; k < this.samples.length; k++) histogram[this.samples[k]]++;
      const total = this.samples.length;
      let low = 0, high = 65535, seen = 0;
      for (let i = 0; i < 65536; i++) { seen += histogram[i]; if (seen >= total * 0.005) { low = i; break; } }
      seen = 0;
      for (let i = 65535; i >= 0; i--) { seen += histogram[i]; if (seen >= total * 0.005) { high = i; break; } }
      this.width.value = Math.max(1, high - low);
      this.level.value = Math.round((low + high) / 2);
    }

    // Samples -> grey through the window, into the bitmap.
    render() {
      if (!this.samples) return;
      const level = Number(this.level.value), width = Math.max(1, Number(this.width.value));
      const lut = new Uint8ClampedArray(65536);
      const low = level - width / 2;
      for (let i = 0; i < 65536; i++) lut[i] = ((i - low) / width) * 255;
      const context = this.bitmap.getContext("2d");
      const image = context.createImageData(this.imageWidth, this.imageHeight);
      const rgba = new Uint32Array(image.data.buffer);
      for (let k = 0; k < this.samples.length; k++) {
        const g = lut[this.samples[k]];
        rgba[k] = 0xff000000 | (g << 16) | (g << 8) | g;
      }
      context.putImageData(image, 0, 0);
      this.draw();
    }

    resize() {
      const box = this.canvas.parentElement.getBoundingClientRect();
      const ratio = window.devicePixelRatio || 1;
      const hadSize = this.cssWidth > 0;
      this.cssWidth = box.width; this.cssHeight = box.height;
      this.canvas.width = Math.max(1, Math.round(box.width * ratio));
      this.canvas.height = Math.max(1, Math.round(box.height * ratio));
      if (!hadSize && this.ready) this.fit();
      this.draw();
    }

    fit() {
      if (!this.ready || !this.cssWidth) return;
      this.scale = Math.min(this.cssWidth / this.imageWidth, this.cssHeight / this.imageHeight) * 0.98;
      this.ox = (this.cssWidth - this.imageWidth * this.scale) / 2;
      this.oy = (this.cssHeight - this.imageHeight * this.scale) / 2;
    }

    toScreen(u, v) { return [this.ox + u * this.scale, this.oy + v * this.scale]; }
    toImage(x, y) { return [(x - this.ox) / this.scale, (y - this.oy) / this.scale]; }

    // Page coordinates (for tests and tools) of image point (u, v).
    toPage(u, v) {
      const rect = this.canvas.getBoundingClientRect();
      const [x, y] = this.toScreen(u, v);
      return { x: rect.left + x, y: rect.top + y };
    }

    draw() {
      const context = this.canvas.getContext("2d");
      const ratio = window.devicePixelRatio || 1;
      context.setTransform(1, 0, 0, 1, 0, 0);
      context.fillStyle = "#000";
      context.fillRect(0, 0, this.canvas.width, this.canvas.height);
      if (!this.ready) return;
      context.setTransform(ratio, 0, 0, ratio, 0, 0);
      context.imageSmoothingEnabled = this.scale < 2;
      context.drawImage(this.bitmap, this.ox, this.oy, this.imageWidth * this.scale, this.imageHeight * this.scale);
      this.station.drawOverlay(this, context);
    }

    listen() {
      const canvas = this.canvas;
      let drag = null;
      canvas.addEventListener("contextmenu", (event) => event.preventDefault());
      canvas.addEventListener("wheel", (event) => {
        event.preventDefault();
        if (!this.ready) return;
        const rect = canvas.getBoundingClientRect();
        const x = event.clientX - rect.left, y = event.clientY - rect.top;
        const [u, v] = this.toImage(x, y);
        const factor = Math.pow(1.0015, -event.deltaY);
        this.scale = Math.min(40, Math.max(0.02, this.scale * factor));
        this.ox = x - u * this.scale; this.oy = y - v * this.scale;
        this.draw();
      }, { passive: false });
      canvas.addEventListener("pointerdown", (event) => {
        if (!this.ready) return;
        canvas.setPointerCapture(event.pointerId);
        drag = {
          button: event.button, x: event.clientX, y: event.clientY, moved: false,
          ox: this.ox, oy: this.oy, level: Number(this.level.value), width: Number(this.width.value),
        };
      });
      canvas.addEventListener("pointermove", (event) => {
        if (!drag) return;
        const dx = event.clientX - drag.x, dy = event.clientY - drag.y;
        if (Math.abs(dx) + Math.abs(dy) > 4) drag.moved = true;
        if (!drag.moved) return;
        if (drag.button === 2) {
          // Right-drag: horizontal = window width, vertical = level.
          this.width.value = Math.max(1, drag.width * Math.pow(1.01, dx));
          this.level.value = drag.level + dy * (drag.width / 300);
          this.render();
        } else {
          this.ox = drag.ox + dx; this.oy = drag.oy + dy;
          this.draw();
        }
      });
      canvas.addEventListener("pointerup", (event) => {
        if (!drag) return;
        const click = !drag.moved && drag.button === 0;
        drag = null;
        if (!click) return;
        const rect = canvas.getBoundingClientRect();
        const [u, v] = this.toImage(event.clientX - rect.left, event.clientY - rect.top);
        this.station.place(this, u, v);
      });
    }
  }

  // ---- the task page -------------------------------------------------------
  let station = null;
  let pollTimer = null;
  function stopPolling() {
    if (pollTimer) clearTimeout(pollTimer);
    pollTimer = null;
  }

  class LandmarkTask {
    constructor(task) {
      this.task = task;
      this.request = task.request;
      this.landmarks = this.request.landmarks || [];
      this.tolerance = Number(this.request.reprojection_tolerance_mm || 3);
      this.points = {};  // name -> view -> [u, v]
      this.errors = {};  // name -> view -> mm (from the last preview)
      this.active = 0;
      this.previewSeq = 0;
      const given = task.submission && task.submission.landmarks;
      if (given && typeof given === "object") {
        for (const [name, views] of Object.entries(given)) this.points[name] = { ...views };
      }
      $("views").innerHTML = "";
      this.views = (this.request.views || []).map((spec) => new View(spec, $("views"), this));
    }

    get mine() { return this.task.state === "claimed" && this.task.assignee === operator; }

    // Shows the landmark panel and its help.
    enter() {
      $("landmark-panel").hidden = false;
      $("review-panel").hidden = true;
      $("submit").textContent = "Submit";
      $("help").textContent = "Click: place the selected landmark · wheel: zoom · drag: pan · " +
        "right-drag: window/level · keys 1-9: select a landmark, F: fit both views";
    }

    get claimedText() { return "Claimed: place the landmarks."; }

    place(view, u, v) {
      if (!this.mine) {
        message("Claim the task to place landmarks.", "bad");
        return;
      }
      if (u < 0 || v < 0 || u > view.imageWidth || v > view.imageHeight) return;
      const landmark = this.landmarks[this.active];
      if (!landmark) return;
      this.points[landmark.name] = this.points[landmark.name] || {};
      this.points[landmark.name][view.spec.name] = [u, v];
      // Both views done: go on to the next landmark without a position.
      const done = (name) => this.views.every((w) => this.points[name] && this.points[name][w.spec.name]);
      if (done(landmark.name)) {
        const next = this.landmarks.findIndex((l, i) => i > this.active && !done(l.name));
        if (next >= 0) this.active = next;
      }
      this.refresh();
      this.preview();
    }

    select(index) {
      if (index >= 0 && index < this.landmarks.length) { this.active = index; this.refresh(); }
    }

    submission() {
      const landmarks = {};
      for (const [name, views] of Object.entries(this.points)) {
        if (Object.keys(views).length) landmarks[name] = views;
      }
      return { landmarks };
    }

    complete() {
      return this.landmarks.filter((l) => l.required).every((l) =>
        this.views.every((w) => this.points[l.name] && this.points[l.name][w.spec.name]));
    }

    async preview() {
      const seq = ++this.previewSeq;
      const submission = this.submission();
      if (!Object.keys(submission.landmarks).length) return this.showPreview([], null);
      try {
        const result = await api("POST", `/api/tasks/${this.task.id}/preview`, submission);
        if (seq === this.previewSeq) this.showPreview(result.reasons, result.values);
      } catch (error) {
        if (seq === this.previewSeq) message(errorText(error), "bad");
      }
    }

    showPreview(reasons, values) {
      this.errors = {};
      for (const landmark of (values && values.landmarks) || []) {
        if (landmark.reprojection_error_mm) this.errors[landmark.name] = landmark.reprojection_error_mm;
      }
      const all = Object.values(this.errors).flatMap((e) => Object.values(e));
      const summary = $("error-summary");
      if (all.length) {
        const worst = Math.max(...all);
        summary.textContent = `Largest reprojection error ${worst.toFixed(2)} mm (tolerance ${this.tolerance} mm)`;
        summary.className = `error-summary ${worst <= this.tolerance ? "good" : "over"}`;
        summary.dataset.maxErrorMm = String(worst);
      } else {
        summary.textContent = "";
        summary.className = "error-summary";
        delete summary.dataset.maxErrorMm;
      }
      $("reasons").innerHTML = (reasons || []).map((r) => `<li>${escape(r)}</li>`).join("");
      this.refresh();
    }

    refresh() {
      const list = $("landmarks");
      list.innerHTML = this.landmarks.map((l, i) => {
        const colour = COLOURS[i % COLOURS.length];
        const places = this.views.map((w) => {
          const placed = this.points[l.name] && this.points[l.name][w.spec.name];
          const error = this.errors[l.name] && this.errors[l.name][w.spec.name];
          const errorText = error === undefined ? "" :
            ` <span class="err ${error <= this.tolerance ? "good" : "over"}" data-error-mm="${error}">${error.toFixed(2)} mm</span>`;
          return `<span class="${placed ? "placed" : "missing"}">${placed ? "✓" : "○"} ${escape(w.spec.name)}${errorText}</span>`;
        }).join("");
        return `<li data-index="${i}" data-name="${escape(l.name)}" class="${i === this.active ? "active" : ""}">` +
          `<span class="swatch" style="background:${colour}"></span><strong>${i + 1}. ${escape(l.label || l.name)}</strong>` +
          `${l.required ? "" : ' <span class="muted">(optional)</span>'}` +
          `<div class="hint">${escape(l.hint || "")}</div>` +
          (i === this.active && l.definition ? `<div class="definition">${escape(l.definition)}</div>` : "") +
          `<div class="places">${places}</div></li>`;
      }).join("");
      this.updateButtons();
      for (const view of this.views) view.draw();
    }

    updateButtons() {
      const state = this.task.state;
      $("claim").hidden = !(state === "open");
      $("release").hidden = !this.mine;
      $("accept-outlines").hidden = true;
      $("submit").hidden = !this.mine;
      $("submit").disabled = !this.complete();
      $("task-state").innerHTML = `${chip(state)} ${this.task.assignee ? "assigned to " + escape(this.task.assignee) : "unassigned"}`;
    }

    drawOverlay(view, context) {
      const active = this.landmarks[this.active];
      // The epipolar (height) line of the active landmark placed in another view.
      if (active && this.points[active.name]) {
        for (const other of this.views) {
          const p = this.points[active.name][other.spec.name];
          if (other === view || !p) continue;
          const curve = epipolarCurve(other.spec, view.spec, p[0], p[1], view.imageWidth, view.imageHeight);
          if (!curve) continue;
          const screen = curve.map(([u, v]) => view.toScreen(u, v));
          context.save();
          context.strokeStyle = COLOURS[this.active % COLOURS.length];
          context.globalAlpha = 0.8;
          context.setLineDash([8, 6]);
          context.lineWidth = 1.5;
          context.beginPath();
          screen.forEach(([x, y], i) => (i === 0 ? context.moveTo(x, y) : context.lineTo(x, y)));
          context.stroke();
          context.restore();
        }
      }
      this.landmarks.forEach((l, i) => {
        const p = this.points[l.name] && this.points[l.name][view.spec.name];
        if (!p) return;
        const [x, y] = view.toScreen(p[0], p[1]);
        const colour = COLOURS[i % COLOURS.length];
        context.save();
        context.strokeStyle = colour;
        context.fillStyle = colour;
        context.lineWidth = i === this.active ? 2.5 : 1.5;
        context.beginPath(); context.arc(x, y, 9, 0, 2 * Math.PI); context.stroke();
        context.beginPath();
        context.moveTo(x - 14, y); context.lineTo(x - 4, y); context.moveTo(x + 4, y); context.lineTo(x + 14, y);
        context.moveTo(x, y - 14); context.lineTo(x, y - 4); context.moveTo(x, y + 4); context.lineTo(x, y + 14);
        context.stroke();
        context.font = "12px system-ui, sans-serif";
        context.fillText(String(i + 1), x + 12, y - 10);
        context.restore();
      });
    }
  }

  // Distance from (u, v) to the segment a-b (pixels).
  function segmentDistance(u, v, a, b) {
    const du = b[0] - a[0], dv = b[1] - a[1];
    const length2 = du * du + dv * dv;
    const t = length2 > 0 ? Math.min(1, Math.max(0, ((u - a[0]) * du + (v - a[1]) * dv) / length2)) : 0;
    return Math.hypot(u - (a[0] + t * du), v - (a[1] + t * dv));
  }

  // A click this far from every outline (screen pixels) picks no bone.
  const PICK_RADIUS_PX = 60;

  class OutlineReviewTask {
    constructor(task) {
      this.task = task;
      this.request = task.request;
      this.bones = this.request.bones || [];
      this.colour = {};
      for (const bone of this.bones) this.colour[bone.name] = bone.colour;
      // Corrections in the order first made: "bone/view" -> {bone, view, points}.
      this.corrections = new Map();
      this.previewSeq = 0;
      const given = task.submission && task.submission.corrections;
      if (Array.isArray(given)) {
        for (const c of given) {
          if (c && Array.isArray(c.points)) {
            this.corrections.set(`${c.bone}/${c.view}`, { bone: c.bone, view: c.view, points: c.points.slice() });
          }
        }
      }
      $("views").innerHTML = "";
      this.views = (this.request.views || []).map((spec) => new View(spec, $("views"), this));
    }

    get mine() { return this.task.state === "claimed" && this.task.assignee === operator; }

    enter() {
      $("landmark-panel").hidden = true;
      $("review-panel").hidden = false;
      $("submit").textContent = "Submit corrections";
      $("help").textContent = "Click near a bone's outline where its true edge is: a correction point for " +
        "the nearest bone in that view · wheel: zoom · drag: pan · right-drag: window/level · F: fit both views";
    }

    get claimedText() { return "Claimed: accept the outlines, or click the true edges and submit corrections."; }

    // The bone whose outline in `view` passes nearest to (u, v): {bone, distance} (pixels).
    nearestBone(view, u, v) {
      let best = null;
      for (const bone of this.bones) {
        for (const polyline of (bone.outlines && bone.outlines[view]) || []) {
          for (let k = 1; k < polyline.length; k++) {
            const distance = segmentDistance(u, v, polyline[k - 1], polyline[k]);
            if (!best || distance < best.distance) best = { bone: bone.name, distance };
          }
        }
      }
      return best;
    }

    place(view, u, v) {
      if (!this.mine) {
        message("Claim the task to correct the outlines.", "bad");
        return;
      }
      if (u < 0 || v < 0 || u > view.imageWidth || v > view.imageHeight) return;
      const nearest = this.nearestBone(view.spec.name, u, v);
      if (!nearest || nearest.distance * view.scale > PICK_RADIUS_PX) {
        message("Click nearer to a bone's outline: the nearest outline picks the bone.", "bad");
        return;
      }
      const key = `${nearest.bone}/${view.spec.name}`;
      if (!this.corrections.has(key)) this.corrections.set(key, { bone: nearest.bone, view: view.spec.name, points: [] });
      this.corrections.get(key).points.push([Math.round(u * 100) / 100, Math.round(v * 100) / 100]);
      message("");
      this.refresh();
      this.preview();
    }

    remove(key, index) {
      const correction = this.corrections.get(key);
      if (!correction) return;
      correction.points.splice(index, 1);
      if (!correction.points.length) this.corrections.delete(key);
      this.refresh();
      this.preview();
    }

    select() {}

    pointCount() {
      let count = 0;
      for (const c of this.corrections.values()) count += c.points.length;
      return count;
    }

    submission() {
      return {
        decision: "correct",
        corrections: [...this.corrections.values()].map((c) => ({ bone: c.bone, view: c.view, points: c.points })),
      };
    }

    complete() { return this.pointCount() > 0; }

    async preview() {
      const seq = ++this.previewSeq;
      if (!this.complete()) return this.showPreview([], null);
      try {
        const result = await api("POST", `/api/tasks/${this.task.id}/preview`, this.submission());
        if (seq === this.previewSeq) this.showPreview(result.reasons, result.values);
      } catch (error) {
        if (seq === this.previewSeq) message(errorText(error), "bad");
      }
    }

    showPreview(reasons) {
      $("reasons").innerHTML = (reasons || []).map((r) => `<li>${escape(r)}</li>`).join("");
      this.refresh();
    }

    refresh() {
      const perBone = {};
      for (const c of this.corrections.values()) perBone[c.bone] = (perBone[c.bone] || 0) + c.points.length;
      $("bones").innerHTML = this.bones.map((b) =>
        `<li data-bone="${escape(b.name)}"><span class="swatch" style="background:${escape(b.colour)}"></span>` +
        `${escape(b.name)}<span class="count">${perBone[b.name] ? perBone[b.name] + " point(s)" : ""}</span></li>`).join("");
      $("corrections").innerHTML = [...this.corrections.entries()].map(([key, c]) =>
        `<li data-key="${escape(key)}" data-bone="${escape(c.bone)}" data-view="${escape(c.view)}">` +
        `<span class="swatch" style="background:${escape(this.colour[c.bone] || "#fff")}"></span> ` +
        `<strong>${escape(c.bone)}</strong> <span class="muted">in ${escape(c.view)}</span><div class="points">` +
        c.points.map((p, i) => `<span class="point">${p[0].toFixed(1)}, ${p[1].toFixed(1)}` +
          `<button class="remove" data-key="${escape(key)}" data-index="${i}" title="Remove this point">×</button></span>`).join("") +
        `</div></li>`).join("");
      $("corrections-empty").hidden = this.corrections.size > 0;
      this.updateButtons();
      for (const view of this.views) view.draw();
    }

    updateButtons() {
      const state = this.task.state;
      $("claim").hidden = !(state === "open");
      $("release").hidden = !this.mine;
      $("accept-outlines").hidden = !this.mine;
      $("accept-outlines").disabled = this.complete();
      $("accept-outlines").title = this.complete() ? "Remove the correction points to accept the outlines as they are" : "";
      $("submit").hidden = !this.mine;
      $("submit").disabled = !this.complete();
      $("task-state").innerHTML = `${chip(state)} ${this.task.assignee ? "assigned to " + escape(this.task.assignee) : "unassigned"}`;
    }

    drawOverlay(view, context) {
      const line = (points) => {
        context.beginPath();
        points.forEach(([u, v], k) => {
          const [x, y] = view.toScreen(u, v);
          if (k === 0) context.moveTo(x, y); else context.lineTo(x, y);
        });
        context.stroke();
      };
      context.save();
      context.lineWidth = 1.5;
      context.globalAlpha = 0.9;
      for (const bone of this.bones) {
        context.strokeStyle = bone.colour;
        for (const polyline of (bone.outlines && bone.outlines[view.spec.name]) || []) line(polyline);
      }
      context.restore();
      for (const c of this.corrections.values()) {
        if (c.view !== view.spec.name) continue;
        const colour = this.colour[c.bone] || "#fff";
        context.save();
        context.strokeStyle = colour;
        context.setLineDash([6, 4]);
        context.lineWidth = 2;
        if (c.points.length > 1) line(c.points);
        context.setLineDash([]);
        for (const [u, v] of c.points) {
          const [x, y] = view.toScreen(u, v);
          context.fillStyle = colour;
          context.strokeStyle = "#fff";
          context.lineWidth = 1.5;
          context.beginPath(); context.arc(x, y, 5, 0, 2 * Math.PI); context.fill(); context.stroke();
        }
        context.restore();
      }
    }
  }

  // The class that shows each kind of task (the request's "kind").
  const TASK_KINDS = { landmarks: LandmarkTask, outline_review: OutlineReviewTask };

  function message(text, kind) {
    const node = $("task-message");
    node.textContent = text || "";
    node.className = `message ${kind || ""}`;
  }

  async function openTask(id) {
    showPage("task");
    message("");
    $("error-summary").textContent = "";
    $("reasons").innerHTML = "";
    let task;
    try {
      task = (await api("GET", `/api/tasks/${id}`)).task;
    } catch (error) {
      $("views").innerHTML = "";
      station = null;
      message(errorText(error), "bad");
      return;
    }
    const Kind = TASK_KINDS[task.request.kind || "landmarks"];
    if (!Kind) {
      $("views").innerHTML = "";
      station = null;
      message(`This page cannot show tasks of kind '${task.request.kind}'; hint: mmm task show ${task.id}`, "bad");
      return;
    }
    station = new Kind(task);
    station.enter();
    window.mmmStation.station = station;
    $("task-title").textContent = `Task ${task.id}`;
    $("task-meta").textContent = `${task.patient} · study ${task.study} · node ${task.node} · opened ${task.age} ago`;
    $("instructions").textContent = task.request.instructions || "";
    station.refresh();
    if (task.rejection_reasons && task.rejection_reasons.length && task.state === "open") {
      message("The last submission was rejected: " + task.rejection_reasons.join("; "), "bad");
    }
    pollStudy(task.study);
    await Promise.all(station.views.map((view) => view.load(task.id).catch((error) => message(errorText(error), "bad"))));
    station.preview();
  }

  async function reloadTask(text, kind) {
    const task = (await api("GET", `/api/tasks/${station.task.id}`)).task;
    station.task = task;
    station.refresh();
    if (text) message(text, kind);
  }

  async function act(action) {
    if (!station) return;
    try {
      await api("POST", `/api/tasks/${station.task.id}/${action}`);
      await reloadTask(action === "claim" ? station.claimedText : "Released.", "ok");
    } catch (error) {
      message(errorText(error), "bad");
    }
  }
  $("claim").addEventListener("click", () => act("claim"));
  $("release").addEventListener("click", () => act("release"));

  // Submits values of the task shown; the outcome replaces its state.
  async function submitValues(submission) {
    if (!station) return;
    $("submit").disabled = true;
    $("accept-outlines").disabled = true;
    try {
      const outcome = await api("POST", `/api/tasks/${station.task.id}/submit`, submission);
      station.task = outcome.task;
      if (outcome.accepted) {
        message("Accepted: the study resumes.", "ok");
      } else if (outcome.awaiting_review) {
        message("Submitted: waiting for a second operator's review.", "ok");
      } else {
        message("Rejected: " + outcome.reasons.join("; ") + " — claim the task again to correct.", "bad");
      }
      station.showPreview(outcome.reasons, outcome.values);
      pollStudy(outcome.study || station.task.study, true);
    } catch (error) {
      message(errorText(error), "bad");
      station.updateButtons();
    }
  }
  $("submit").addEventListener("click", () => station && submitValues(station.submission()));
  $("accept-outlines").addEventListener("click", () => submitValues({ decision: "accept" }));

  // The study's node states, every second while the task page is open.
  async function pollStudy(study, soon) {
    stopPolling();
    if (!study) return;
    const path = `/api/studies/${study.split("/").map(encodeURIComponent).join("/")}/status`;
    const tick = async () => {
      try {
        const status = await api("GET", path);
        const badge = $("study-state");
        badge.textContent = status.state;
        badge.className = `chip ${status.state}`;
        $("task").dataset.studyState = status.state;
        $("study-nodes").innerHTML = status.nodes.map((n) =>
          `<li data-node="${escape(n.name)}" data-state="${escape(n.state)}" title="${escape(n.reason)}">` +
          `<span>${escape(n.name)}</span>${chip(escape(n.state === "cached" ? "done" : n.state))}</li>`).join("");
      } catch (error) {
        if (error.status === 401) return;
      }
      if ($("task").hidden) return;
      pollTimer = setTimeout(tick, 1000);
    };
    if (soon) pollTimer = setTimeout(tick, 300);
    else tick();
  }

  document.addEventListener("keydown", (event) => {
    if (!station || $("task").hidden || event.target.tagName === "INPUT") return;
    if (event.key >= "1" && event.key <= "9") station.select(Number(event.key) - 1);
    if (event.key === "f" || event.key === "F") for (const view of station.views) { view.fit(); view.draw(); }
  });
  $("landmarks").addEventListener("click", (event) => {
    const item = event.target.closest("li[data-index]");
    if (item && station) station.select(Number(item.dataset.index));
  });
  $("corrections").addEventListener("click", (event) => {
    const button = event.target.closest("button.remove");
    if (button && station && station.remove) station.remove(button.dataset.key, Number(button.dataset.index));
  });

  // For tests and tools: where image point (u, v) of a view is on the page.
  window.mmmStation = {
    station: null,
    ready: () => Boolean(station && station.views.length && station.views.every((v) => v.ready)),
    imageToPage: (view, u, v) => station.views.find((w) => w.spec.name === view).toPage(u, v),
  };

  start();
})();
