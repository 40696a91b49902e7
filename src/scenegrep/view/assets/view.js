// scenegrep trace view: draws one trace (top-down map or image boxes) frame by frame, with the
// matches of a query: window on the time line, corresponded objects highlighted and labelled.
// Reads the JSON document in #scenegrep-data (see scenegrep/view/payload.py for its fields).
(function () {
  "use strict";
  const data = JSON.parse(document.getElementById("scenegrep-data").textContent);
  const $ = (id) => document.getElementById(id);
  const nFrames = data.frames.index.length;
  const rowOfId = new Map(data.objects.id.map((id, k) => [id, k]));
  const state = { frame: 0, match: -1, channel: 0, playing: null, view: { scale: 1, ox: 0, oy: 0 }, drawn: [] };

  // The rows drawn: the states, or the boxes of the image channel shown (one table per channel).
  let rows, rowsOfObject, frameOfRow;
  function useRows(table) {
    rows = table;
    // Rows of every object, in frame order (for paths and the label rows of the time line).
    rowsOfObject = data.objects.id.map(() => []);
    for (let r = 0; r < rows.object.length; r++) if (rows.object[r] >= 0) rowsOfObject[rows.object[r]].push(r);
    frameOfRow = new Int32Array(rows.object.length);
    for (let f = 0; f < nFrames; f++) for (let r = rows.offsets[f]; r < rows.offsets[f + 1]; r++) frameOfRow[r] = f;
  }
  useRows(data.space === "image" ? data.boxes[0] : data.states);

  function currentMatch() { return state.match >= 0 ? data.matches[state.match] : null; }

  // Object row -> program name of the current match.
  function highlights() {
    const out = new Map();
    const m = currentMatch();
    if (!m) return out;
    for (const [name, id] of Object.entries(m.correspondence)) if (rowOfId.has(id)) out.set(rowOfId.get(id), name);
    return out;
  }

  // ---------------------------------------------------------------- geometry
  function corners(r) {
    if (data.space === "image") {
      const c = Math.cos(rows.rotation[r]), s = Math.sin(rows.rotation[r]);
      const hw = rows.w[r] / 2, hh = rows.h[r] / 2;
      return [[-hw, -hh], [hw, -hh], [hw, hh], [-hw, hh]].map(([u, v]) =>
        [rows.cx[r] + u * c - v * s, rows.cy[r] + u * s + v * c]);
    }
    const h = rows.heading[r], fx = -Math.sin(h), fy = Math.cos(h);
    const l = Math.max(rows.length[r], 0.5) / 2, w = Math.max(rows.width[r], 0.5) / 2;
    return [[l, w], [l, -w], [-l, -w], [-l, w]].map(([a, b]) =>
      [rows.x[r] + a * fx + b * fy, rows.y[r] + a * fy - b * fx]);
  }
  function position(r) {
    return data.space === "image" ? [rows.cx[r], rows.cy[r]] : [rows.x[r], rows.y[r]];
  }
  function contains(poly, p) {
    let inside = false;
    for (let i = 0, j = poly.length - 1; i < poly.length; j = i++) {
      const [xi, yi] = poly[i], [xj, yj] = poly[j];
      if ((yi > p[1]) !== (yj > p[1]) && p[0] < ((xj - xi) * (p[1] - yi)) / (yj - yi) + xi) inside = !inside;
    }
    return inside;
  }

  // ---------------------------------------------------------------- view transform
  const canvas = $("scene"), ctx = canvas.getContext("2d");
  const flipY = data.space !== "image";
  function toScreen(p) {
    const v = state.view;
    return [(p[0] - v.ox) * v.scale, flipY ? canvas.height - (p[1] - v.oy) * v.scale : (p[1] - v.oy) * v.scale];
  }
  function toWorld(sx, sy) {
    const v = state.view;
    return [sx / v.scale + v.ox, (flipY ? canvas.height - sy : sy) / v.scale + v.oy];
  }
  function extent() {
    if (data.space === "image") return [0, 0, rows.image_size[0] || 1600, rows.image_size[1] || 900];
    const m = currentMatch();
    const pick = m ? [...highlights().keys()].flatMap((o) => rowsOfObject[o]) : [...rows.x.keys()];
    const use = pick.length ? pick : [...rows.x.keys()];
    let x0 = Infinity, y0 = Infinity, x1 = -Infinity, y1 = -Infinity;
    for (const r of use) {
      if (rows.x[r] === null) continue;
      x0 = Math.min(x0, rows.x[r]); x1 = Math.max(x1, rows.x[r]);
      y0 = Math.min(y0, rows.y[r]); y1 = Math.max(y1, rows.y[r]);
    }
    if (!isFinite(x0)) return [0, 0, 100, 100];
    const pad = 15;
    return [x0 - pad, y0 - pad, x1 + pad, y1 + pad];
  }
  function fit() {
    const rect = canvas.getBoundingClientRect();
    canvas.width = Math.max(rect.width, 200);
    canvas.height = Math.max(rect.height, 200);
    const [x0, y0, x1, y1] = extent();
    const scale = Math.min(canvas.width / (x1 - x0), canvas.height / (y1 - y0));
    state.view = {
      scale,
      ox: x0 - (canvas.width / scale - (x1 - x0)) / 2,
      oy: y0 - (canvas.height / scale - (y1 - y0)) / 2,
    };
  }

  // ---------------------------------------------------------------- drawing
  const scene = data.scene_colours; // [fill, edge] of the backgrounds, map layers, image area, time line (style.py)
  function colour(c) { return c === "none" ? null : c; }
  function polygon(points, fill, stroke, width) {
    ctx.beginPath();
    points.forEach((p, k) => { const [sx, sy] = toScreen(p); if (k) ctx.lineTo(sx, sy); else ctx.moveTo(sx, sy); });
    ctx.closePath();
    if (fill) { ctx.fillStyle = fill; ctx.fill(); }
    if (stroke) { ctx.strokeStyle = stroke; ctx.lineWidth = width || 1; ctx.stroke(); }
  }
  function drawMap() {
    if (!data.map) return;
    ctx.globalAlpha = 0.9; // as the pictures
    for (const layer of ["lane", "intersection", "crosswalk"]) {
      const [fill, edge] = scene[layer].map(colour);
      for (const ring of data.map[`${layer}s`]) polygon(ring, fill, edge, 1);
    }
    ctx.globalAlpha = 1;
  }
  function drawImageFrame() {
    const [w, h] = rows.image_size;
    polygon([[0, 0], [w || 1600, 0], [w || 1600, h || 900], [0, h || 900]], ...scene.image.map(colour), 1);
  }
  function drawPaths(hl) {
    const m = currentMatch();
    if (!m) return;
    for (const [o, name] of hl) {
      const path = rowsOfObject[o].filter((r) => frameOfRow[r] >= m.first && frameOfRow[r] <= m.last);
      if (path.length < 2) continue;
      ctx.beginPath();
      path.forEach((r, k) => { const [sx, sy] = toScreen(position(r)); if (k) ctx.lineTo(sx, sy); else ctx.moveTo(sx, sy); });
      ctx.strokeStyle = data.program_colours[name];
      ctx.globalAlpha = 0.6; ctx.lineWidth = 2; ctx.setLineDash([6, 4]); ctx.stroke();
      ctx.setLineDash([]); ctx.globalAlpha = 1;
    }
  }
  function drawObjects(hl) {
    const labels = [];
    state.drawn = [];
    const m = currentMatch();
    const inWindow = m && state.frame >= m.first && state.frame <= m.last;
    for (let r = rows.offsets[state.frame]; r < rows.offsets[state.frame + 1]; r++) {
      const o = rows.object[r];
      const name = o >= 0 ? hl.get(o) : undefined;
      const marked = inWindow && rows.marked.length && rows.marked[r];
      // an object's kind, else (an image box of no object) its class's kind
      const kindColour = o >= 0 ? data.objects.colour[o] : rows.class_colours[rows.class[r]];
      const pts = corners(r);
      state.drawn.push([r, name !== undefined ? data.program_colours[name] : kindColour]);
      if (name !== undefined) {
        polygon(pts, data.program_colours[name], "#111", 2);
        labels.push([pts, name]);
      } else if (data.space === "image") {
        polygon(pts, null, marked ? data.marked_colour : kindColour, marked ? 3 : 1.5);
      } else {
        polygon(pts, kindColour, marked ? data.marked_colour : (o >= 0 && data.objects.id[o] === data.ego ? "#111" : null),
          marked ? 3 : 1.5);
      }
      if (data.space !== "image") {
        const [cx, cy] = toScreen(position(r));
        const [fx, fy] = toScreen([rows.x[r] - Math.sin(rows.heading[r]) * rows.length[r] / 2,
          rows.y[r] + Math.cos(rows.heading[r]) * rows.length[r] / 2]);
        ctx.beginPath(); ctx.moveTo(cx, cy); ctx.lineTo(fx, fy);
        ctx.strokeStyle = "rgba(255, 255, 255, 0.8)"; ctx.lineWidth = 1; ctx.stroke();
      }
    }
    ctx.font = "bold 13px system-ui, sans-serif";
    for (const [pts, name] of labels) {
      const top = pts.map(toScreen).reduce((a, b) => (a[1] < b[1] ? a : b));
      ctx.lineWidth = 3; ctx.strokeStyle = "#fff"; ctx.strokeText(name, top[0] + 4, top[1] - 4);
      ctx.fillStyle = "#111"; ctx.fillText(name, top[0] + 4, top[1] - 4);
    }
  }
  function draw() {
    ctx.fillStyle = scene.background[0]; ctx.fillRect(0, 0, canvas.width, canvas.height);
    const hl = highlights();
    if (data.space === "image") drawImageFrame(); else drawMap();
    drawPaths(hl);
    drawObjects(hl);
    drawCursor();
    document.body.dataset.frame = String(state.frame);
  }

  // ---------------------------------------------------------------- time line
  const labelCanvas = $("labels"), lctx = labelCanvas.getContext("2d");
  function drawLabelRows(hl, step, rowHeight) {
    const seen = new Set();
    hl.forEach(([o, name], k) => {
      for (const r of rowsOfObject[o]) {
        const code = rows.labels[r];
        seen.add(code);
        lctx.fillStyle = rows.label_colours[code];
        lctx.fillRect(frameOfRow[r] * step, k * rowHeight + 1, Math.ceil(step), rowHeight - 2);
      }
      lctx.fillStyle = "#111"; lctx.font = "bold 11px system-ui, sans-serif";
      lctx.fillText(name, 3, k * rowHeight + Math.min(rowHeight - 3, 12));
    });
    const legend = $("label-legend");
    legend.replaceChildren();
    for (const code of [...seen].sort((a, b) => a - b)) {
      const item = document.createElement("span");
      const sw = document.createElement("i"); sw.style.background = rows.label_colours[code];
      item.append(sw, rows.label_names[code] || "(none)");
      legend.append(item);
    }
  }
  function drawCounts(step) {
    // Without corresponded objects: objects per frame (grey) and those of the query's classes (orange).
    let most = 1;
    for (let f = 0; f < nFrames; f++) most = Math.max(most, rows.offsets[f + 1] - rows.offsets[f]);
    for (let f = 0; f < nFrames; f++) {
      let marked = 0;
      for (let r = rows.offsets[f]; r < rows.offsets[f + 1]; r++) if (rows.marked.length && rows.marked[r]) marked++;
      const all = rows.offsets[f + 1] - rows.offsets[f], h = labelCanvas.height;
      lctx.fillStyle = scene.count[0]; lctx.fillRect(f * step, h - (h * all) / most, Math.ceil(step), (h * all) / most);
      lctx.fillStyle = data.marked_colour; lctx.fillRect(f * step, h - (h * marked) / most, Math.ceil(step), (h * marked) / most);
    }
    $("label-legend").innerHTML = rows.marked.length
      ? `<span><i style="background:${scene.count[0]}"></i>objects per frame</span>` +
        `<span><i style="background:${data.marked_colour}"></i>of the classes the query names</span>`
      : `<span><i style="background:${scene.count[0]}"></i>objects per frame</span>`;
  }
  function drawTimeline() {
    const rect = labelCanvas.getBoundingClientRect();
    labelCanvas.width = Math.max(rect.width, 100);
    labelCanvas.height = Math.max(rect.height, 20);
    lctx.clearRect(0, 0, labelCanvas.width, labelCanvas.height);
    lctx.fillStyle = scene.timeline[0]; lctx.fillRect(0, 0, labelCanvas.width, labelCanvas.height);
    const hl = [...highlights()];
    const step = labelCanvas.width / nFrames;
    // label rows of the corresponded objects where the trace has behaviour labels, as the pictures
    if (hl.length && data.space !== "image" && rows.labels.length) drawLabelRows(hl, step, labelCanvas.height / hl.length);
    else drawCounts(step);
    const m = currentMatch(), mark = $("window-mark");
    mark.hidden = !m;
    if (m) {
      lctx.fillStyle = "rgba(255, 255, 255, 0.55)";
      lctx.fillRect(0, 0, m.first * step, labelCanvas.height);
      lctx.fillRect((m.last + 1) * step, 0, labelCanvas.width, labelCanvas.height);
      mark.style.left = `${(100 * m.first) / nFrames}%`;
      mark.style.width = `${(100 * (m.last - m.first + 1)) / nFrames}%`;
      mark.dataset.first = String(data.frames.index[m.first]);
      mark.dataset.last = String(data.frames.index[m.last]);
    }
  }
  function drawCursor() {
    $("cursor").style.left = `${(100 * (state.frame + 0.5)) / nFrames}%`;
    $("frame").value = String(state.frame);
    const t = data.frames.time[state.frame];
    $("frame-label").textContent = `frame ${data.frames.index[state.frame]} (${state.frame + 1} of ${nFrames})` +
      (t === null ? "" : ` · ${t.toFixed(2)} s`);
  }

  // ---------------------------------------------------------------- panels
  function showMatch(k) {
    state.match = k;
    const m = currentMatch();
    const legend = $("legend");
    legend.replaceChildren();
    if (m) {
      for (const [name, id] of Object.entries(m.correspondence)) {
        const li = document.createElement("li");
        li.dataset.name = name; li.dataset.id = id;
        const sw = document.createElement("span"); sw.className = "swatch"; sw.style.background = data.program_colours[name];
        const nm = document.createElement("b"); nm.textContent = name;
        const oid = document.createElement("span"); oid.className = "id";
        oid.textContent = `${id} (${data.objects.category[rowOfId.get(id)]})`;
        li.append(sw, nm, oid); legend.append(li);
      }
      const t0 = data.frames.time[m.first], t1 = data.frames.time[m.last];
      const seconds = t0 === null || t1 === null ? "" : `${t0.toFixed(1)}–${t1.toFixed(1)} s, `;
      $("window").textContent = `frames ${data.frames.index[m.first]}–${data.frames.index[m.last]} ` +
        `(${seconds}${m.last - m.first + 1} frames)`;
      $("explanation").textContent = m.explanation || "(the run did not ask for explanations: rerun with --explain)";
      state.frame = m.first;
    } else {
      $("window").textContent = data.matches.length ? "" : "no match";
      $("explanation").textContent = data.note || "(no match shown)";
    }
    if (rows.marked.length) {
      const li = document.createElement("li");
      li.innerHTML = `<span class="swatch" style="border: 3px solid ${data.marked_colour}"></span>` +
        "<span>objects of the classes the query names (in the window)</span>";
      legend.append(li);
    }
    if (!legend.children.length) legend.innerHTML = "<li>none</li>";
    $("match").value = String(k);
    fit(); drawTimeline(); draw();
  }
  function setupPanels() {
    $("title").textContent = data.name;
    $("query").textContent = data.query ? `${data.query.kind}: ${data.query.text}` : "(a trace without a query)";
    const select = $("match");
    data.matches.forEach((m, k) => {
      const o = document.createElement("option"); o.value = String(k);
      o.textContent = `${m.number} · frames ${data.frames.index[m.first]}–${data.frames.index[m.last]}`;
      select.append(o);
    });
    if (!data.matches.length) $("match-choice").hidden = true;
    select.addEventListener("change", () => showMatch(Number(select.value)));
    const channels = $("channel");
    if (data.space === "image") {
      data.boxes.forEach((table, k) => {
        const o = document.createElement("option"); o.value = String(k); o.textContent = table.channel;
        channels.append(o);
      });
      channels.disabled = data.boxes.length < 2;
      channels.addEventListener("change", () => showChannel(Number(channels.value)));
    } else {
      $("channel-choice").hidden = true;
    }
  }
  function showChannel(k) {
    state.channel = Math.max(0, Math.min(data.boxes.length - 1, k));
    useRows(data.boxes[state.channel]);
    $("channel").value = String(state.channel);
    fit(); drawTimeline(); draw();
  }

  // ---------------------------------------------------------------- interaction
  function setFrame(f) {
    state.frame = Math.max(0, Math.min(nFrames - 1, Math.round(f)));
    draw();
  }
  function togglePlay() {
    if (state.playing) { clearInterval(state.playing); state.playing = null; $("play").innerHTML = "&#9654;"; return; }
    const m = currentMatch();
    if (state.frame >= nFrames - 1) setFrame(m ? m.first : 0);
    const times = data.frames.time;
    const step = nFrames > 1 ? (1000 * (times[nFrames - 1] - times[0])) / (nFrames - 1) : NaN;
    const period = Number.isFinite(step) ? Math.max(20, step) : 100; // streams without timestamps: 10 frames/s
    $("play").innerHTML = "&#10074;&#10074;";
    state.playing = setInterval(() => {
      if (state.frame >= nFrames - 1) togglePlay(); else setFrame(state.frame + 1);
    }, period);
  }
  function hover(event) {
    const rect = canvas.getBoundingClientRect();
    const sx = event.clientX - rect.left, sy = event.clientY - rect.top;
    const p = toWorld(sx * (canvas.width / rect.width), sy * (canvas.height / rect.height));
    const tip = $("tooltip");
    for (let r = rows.offsets[state.frame + 1] - 1; r >= rows.offsets[state.frame]; r--) {
      if (!contains(corners(r), p)) continue;
      tip.textContent = describe(r);
      tip.style.left = `${sx + 14}px`; tip.style.top = `${sy + 14}px`;
      tip.hidden = false;
      return;
    }
    tip.hidden = true;
  }
  function describe(r) {
    const o = rows.object[r];
    const name = o >= 0 ? highlights().get(o) : undefined;
    const lines = [];
    if (name !== undefined) lines.push(`${name} (program object)`);
    if (o >= 0) lines.push(`id ${data.objects.id[o]}`, `class ${data.objects.category[o]} (${data.objects.kind[o]})`);
    if (data.space === "image") {
      lines.push(`class ${rows.classes[rows.class[r]]}`, `centre ${rows.cx[r]}, ${rows.cy[r]} px`,
        `size ${rows.w[r]} x ${rows.h[r]} px`, `score ${rows.score[r]}`);
    } else {
      lines.push(`position ${rows.x[r]}, ${rows.y[r]} m`, `heading ${(rows.heading[r] * 180 / Math.PI).toFixed(1)} deg`,
        `size ${rows.length[r]} x ${rows.width[r]} m`);
      if (rows.speed[r] !== null) lines.push(`speed ${rows.speed[r]} m/s`);
      if (rows.labels.length) lines.push(`behaviours ${rows.label_names[rows.labels[r]] || "none"}`);
    }
    return lines.join("\n");
  }
  function setupInteraction() {
    const slider = $("frame");
    slider.max = String(nFrames - 1);
    slider.addEventListener("input", () => setFrame(Number(slider.value)));
    $("play").addEventListener("click", togglePlay);
    $("timeline").addEventListener("click", (e) => {
      const rect = $("timeline").getBoundingClientRect();
      setFrame(((e.clientX - rect.left) / rect.width) * nFrames - 0.5);
    });
    canvas.addEventListener("mousemove", (e) => { if (!drag) hover(e); });
    canvas.addEventListener("mouseleave", () => { $("tooltip").hidden = true; });
    let drag = null;
    canvas.addEventListener("mousedown", (e) => { drag = [e.clientX, e.clientY]; });
    window.addEventListener("mouseup", () => { drag = null; });
    window.addEventListener("mousemove", (e) => {
      if (!drag) return;
      const ratio = canvas.width / canvas.getBoundingClientRect().width;
      state.view.ox -= ((e.clientX - drag[0]) * ratio) / state.view.scale;
      state.view.oy += (((e.clientY - drag[1]) * ratio) / state.view.scale) * (flipY ? 1 : -1);
      drag = [e.clientX, e.clientY];
      draw();
    });
    canvas.addEventListener("wheel", (e) => {
      e.preventDefault();
      const rect = canvas.getBoundingClientRect();
      const sx = (e.clientX - rect.left) * (canvas.width / rect.width);
      const sy = (e.clientY - rect.top) * (canvas.height / rect.height);
      const before = toWorld(sx, sy);
      state.view.scale *= Math.exp(-e.deltaY * 0.0015);
      const after = toWorld(sx, sy);
      state.view.ox += before[0] - after[0];
      state.view.oy += before[1] - after[1];
      draw();
    }, { passive: false });
    canvas.addEventListener("dblclick", () => { fit(); draw(); });
    window.addEventListener("resize", () => { fit(); drawTimeline(); draw(); });
    window.addEventListener("keydown", (e) => {
      if (["SELECT", "INPUT"].includes(e.target.tagName) && e.key !== " ") return; // they move themselves
      if (e.key === " ") { e.preventDefault(); togglePlay(); }
      if (e.key === "ArrowRight") setFrame(state.frame + 1);
      if (e.key === "ArrowLeft") setFrame(state.frame - 1);
    });
  }

  // For tests and scripts: the state the page shows.
  window.scenegrepView = {
    frame: () => data.frames.index[state.frame],
    setFrame,
    match: () => (currentMatch() ? currentMatch().number : null),
    channel: () => (data.space === "image" ? rows.channel : null),
    setChannel: (name) => showChannel(data.boxes.findIndex((table) => table.channel === name)),
    // [row, colour] of every box drawn in the frame shown: its program name's, kind's or class's colour
    drawnColours: () => state.drawn.map(([r, colour]) => [r, colour]),
    window: () => { const m = currentMatch(); return m ? [data.frames.index[m.first], data.frames.index[m.last]] : null; },
    highlighted: () => {
      const hl = highlights(), out = [];
      for (let r = rows.offsets[state.frame]; r < rows.offsets[state.frame + 1]; r++) {
        if (hl.has(rows.object[r])) out.push([hl.get(rows.object[r]), data.objects.id[rows.object[r]]]);
      }
      return out;
    },
    screenOf: (id) => {
      const o = rowOfId.get(id);
      for (let r = rows.offsets[state.frame]; r < rows.offsets[state.frame + 1]; r++) {
        if (rows.object[r] !== o) continue;
        const [sx, sy] = toScreen(position(r)), rect = canvas.getBoundingClientRect();
        return [rect.left + (sx * rect.width) / canvas.width, rect.top + (sy * rect.height) / canvas.height];
      }
      return null;
    },
    marked: () => {
      const out = [];
      for (let r = rows.offsets[state.frame]; r < rows.offsets[state.frame + 1]; r++) if (rows.marked[r]) out.push(r);
      return out;
    },
  };

  setupPanels();
  setupInteraction();
  const wanted = /match=(\d+)/.exec(location.hash);
  const initial = wanted ? wanted[1] : document.body.dataset.initialMatch;
  const chosen = initial ? data.matches.findIndex((m) => m.number === Number(initial)) : 0;
  showMatch(data.matches.length ? Math.max(chosen, 0) : -1);
})();
