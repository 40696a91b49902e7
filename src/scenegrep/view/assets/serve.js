// scenegrep serve: the dataset page. Lists traces and runs, sends queries to /api/query and
// lists the matches, each linked to its view (/view/TRACE?run=RUN#match=N). Every API call
// carries the token the server put on <body> (data-token), which pages elsewhere never see.
(function () {
  "use strict";
  const $ = (id) => document.getElementById(id);
  const EXAMPLES = {
    spre: "[[:pedestrian:]]+",
    scene: "model scenic.domains.driving.model\nego = new Car on road\notherCar = new Car ahead of ego by Range(4, 10)",
    scenario: "model scenic.simulators.newtonian.driving_model\nbehavior EgoBehavior():\n    try:\n" +
      "        do FollowLaneBehavior()\n    interrupt when (distance to parkedCar) < Range(1, 15):\n" +
      "        do LaneChangeBehavior()\n        do FollowLaneBehavior()\n" +
      "ego = new Car with behavior EgoBehavior()\nparkedCar = new Car on visible ego.lane",
  };
  function cell(row, content) {
    const td = document.createElement("td");
    if (content instanceof Node) td.append(content); else td.textContent = content;
    row.append(td);
  }
  function link(href, text) {
    const a = document.createElement("a"); a.href = href; a.textContent = text; return a;
  }
  async function getJson(url, init = {}) {
    const token = { [document.body.dataset.tokenHeader]: document.body.dataset.token };
    const response = await fetch(url, { ...init, headers: { ...(init.headers || {}), ...token } });
    const body = await response.json();
    if (!response.ok) throw new Error(body.error || response.statusText);
    return body;
  }
  function showKind() {
    const kind = $("kind").value;
    for (const el of document.querySelectorAll(".scenario-only")) el.hidden = kind !== "scenario";
    for (const el of document.querySelectorAll(".scenic-only")) el.hidden = kind === "spre";
    $("text").placeholder = EXAMPLES[kind];
  }
  function options() {
    const kind = $("kind").value, out = {};
    if (kind === "spre") return out;
    const number = (id) => ($(id).value.trim() === "" ? null : Number($(id).value));
    out.tolerance_position = number("tolerance-position");
    out.tolerance_heading = number("tolerance-heading");
    out.explain = $("explain").checked;
    if (kind === "scenario") { out.window = $("window").value.trim(); out.all = $("all").checked; }
    return out;
  }
  async function runQuery(event) {
    event.preventDefault();
    $("error").hidden = true;
    $("status").textContent = "running…";
    $("run").disabled = true;
    try {
      const body = JSON.stringify({ kind: $("kind").value, text: $("text").value, options: options() });
      const answer = await getJson("/api/query", { method: "POST", headers: { "Content-Type": "application/json" }, body });
      showResults(answer);
      $("status").textContent = `run ${answer.run_id} ${answer.status}`;
      loadRuns();
    } catch (error) {
      $("error").textContent = error.message;
      $("error").hidden = false;
      $("status").textContent = "";
    } finally {
      $("run").disabled = false;
    }
  }
  function showResults(answer) {
    const c = answer.counts;
    $("counts").replaceChildren(
      `${answer.matches.length} matches in ${c.matched} of ${c.traces} traces (${c.pruned} pruned, ${c.failed} failed) · `,
      link(answer.report, "report"));
    const body = $("matches").querySelector("tbody");
    body.replaceChildren();
    answer.matches.forEach((m, k) => {
      const row = document.createElement("tr");
      const a = link(m.href, `${m.name} · ${m.match}`);
      a.className = "match-link";
      Object.assign(a.dataset, { trace: m.trace_id, match: m.match, start: m.start_frame, end: m.end_frame,
        correspondence: m.correspondence || "{}" });
      cell(row, String(k)); cell(row, a); cell(row, `${m.start_frame}–${m.end_frame}`);
      cell(row, `${m.start_time.toFixed(1)}–${m.end_time.toFixed(1)}`);
      cell(row, Object.entries(JSON.parse(m.correspondence || "{}")).map(([n, o]) => `${n} = ${o}`).join(", "));
      body.append(row);
    });
    $("results").hidden = false;
  }
  async function loadTraces() {
    const traces = await getJson("/api/traces");
    $("dataset-summary").textContent = `${traces.length} traces`;
    const body = $("traces").querySelector("tbody");
    for (const t of traces) {
      const row = document.createElement("tr");
      row.dataset.name = t.name.toLowerCase();
      cell(row, link(`/view/${encodeURIComponent(t.trace_id)}`, t.name));
      cell(row, String(t.frames)); cell(row, t.duration_s.toFixed(1)); cell(row, String(t.objects));
      cell(row, t.has_behaviours ? "yes" : "no"); cell(row, t.has_images ? "yes" : "no");
      body.append(row);
    }
  }
  async function loadRuns() {
    const runs = await getJson("/api/runs");
    const body = $("runs").querySelector("tbody");
    body.replaceChildren();
    for (const r of runs) {
      const row = document.createElement("tr");
      cell(row, link(`/report/${r.run_id}`, r.run_id)); cell(row, r.kind);
      cell(row, r.query.length > 80 ? r.query.slice(0, 79) + "…" : r.query);
      cell(row, r.status); cell(row, `${r.matched} / ${r.traces}`);
      body.append(row);
    }
  }
  $("kind").addEventListener("change", showKind);
  $("query-form").addEventListener("submit", runQuery);
  $("filter").addEventListener("input", () => {
    const words = $("filter").value.toLowerCase();
    for (const row of $("traces").querySelectorAll("tbody tr")) row.hidden = !row.dataset.name.includes(words);
  });
  showKind();
  loadTraces();
  loadRuns();
})();
