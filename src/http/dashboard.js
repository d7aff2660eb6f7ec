"use strict";
// Who is signed in and what the page shows for them. `epoch` changes on every sign-in and
// sign-out: an answer that arrives for an earlier epoch is dropped, so nothing a previous
// token fetched reaches the page after it changed.
const state = { token: "", me: null, timer: null, epoch: 0, polling: false, ticks: 0, route: null };

// The token lives in this tab's sessionStorage only (gone when the tab closes; never in
// localStorage, which every later visitor of the browser profile could read). A token handed
// over in the URL's fragment is taken and removed from the address bar.
function readToken() {
  localStorage.removeItem("railwear-token"); // left by earlier versions of this page
  const fromHash = new URLSearchParams(location.hash.slice(1)).get("token");
  if (fromHash) {
    sessionStorage.setItem("railwear-token", fromHash);
    history.replaceState(null, "", location.pathname + location.search);
  }
  state.token = fromHash || sessionStorage.getItem("railwear-token") || "";
  document.getElementById("token").value = state.token;
}

// Empties every view and stops polling: what the last token fetched is gone.
function clearAll() {
  state.epoch += 1;
  if (state.timer !== null) { clearInterval(state.timer); state.timer = null; }
  state.me = null;
  diag.may = false; diag.shown = null; diag.started = null; diag.starting.clear(); diag.campaigns.clear(); diag.jobs.clear();
  state.ticks = 0; state.polling = false;
  for (const id of ["jobs", "campaigns", "diagnoses", "rails", "measurements", "curves"]) { document.getElementById(id).replaceChildren(); }
  for (const id of ["report", "curve", "diagnosis", "whoami", "diagnoses-error", "diagnose-error", "job-page",
    "curves-error", "jobs-note"]) {
    document.getElementById(id).replaceChildren();
  }
  jobPage.id = null; jobPage.status = null;
  jobList.cursors = [null]; jobList.index = 0; jobList.next = null; jobList.key = "";
  state.route = null;
  showView(null);
  const out = document.getElementById("diagnosis");
  delete out.dataset.job; delete out.dataset.verdict; delete out.dataset.status;
  delete document.getElementById("whoami").dataset.role;
  document.getElementById("diagnose-options").hidden = true;
  document.getElementById("submit-job").hidden = true;
  document.getElementById("upload-campaign").hidden = true;
  document.getElementById("record-measurement").hidden = true;
  for (const id of ["submit-error", "upload-error", "m-error"]) { document.getElementById(id).textContent = ""; }
}

function signOut() {
  clearAll();
  sessionStorage.removeItem("railwear-token");
  state.token = "";
  document.getElementById("token").value = "";
  document.getElementById("error").textContent = "signed out";
}

// A token the service refuses (401): nothing of the previous user stays, polling stops.
function refused(detail) {
  clearAll();
  sessionStorage.removeItem("railwear-token");
  state.token = "";
  document.getElementById("error").textContent = "token refused (" + detail + "); enter another";
}

// Signs in with the token in the field: asks who it is, then polls every second.
async function signIn() {
  clearAll();
  const epoch = state.epoch;
  const error = document.getElementById("error");
  if (!state.token) { error.textContent = "enter a token"; return; }
  error.textContent = "";
  let me;
  try { me = await api("/v1/whoami"); } catch (e) {
    if (epoch === state.epoch && !(e instanceof Refused)) { error.textContent = String(e); }
    return;
  }
  if (epoch !== state.epoch) { return; }
  state.me = me;
  diag.may = me.may.diagnose;
  const who = document.getElementById("whoami");
  who.replaceChildren(document.createTextNode("signed in as "), text("strong", me.name, "who-name"),
    document.createTextNode(" (" + me.role + ")"));
  who.dataset.role = me.role;
  document.getElementById("diagnose-options").hidden = !diag.may;
  document.getElementById("submit-job").hidden = !me.may.submit_jobs;
  document.getElementById("upload-campaign").hidden = !me.may.upload_campaigns;
  document.getElementById("record-measurement").hidden = !me.may.record_measurements;
  route();
  state.timer = setInterval(poll, 1000);
  poll();
}

// Thrown after a 401 (the page has already cleared itself).
class Refused extends Error {}

async function api(path, init) {
  const options = init || {};
  const epoch = state.epoch;
  options.headers = Object.assign({ "Authorization": "Bearer " + state.token }, options.headers || {});
  const response = await fetch(path, options);
  const type = response.headers.get("content-type") || "";
  const body = type.includes("json") ? await response.json() : await response.text();
  if (epoch !== state.epoch) { throw new Refused("signed out meanwhile"); }
  if (response.status === 401) {
    const detail = "401: " + (body && body.detail ? body.detail : response.statusText);
    refused(detail);
    throw new Refused(detail);
  }
  if (!response.ok) {
    const detail = body && body.detail ? body.detail : response.statusText;
    throw new Error(response.status + ": " + detail);
  }
  return body;
}

function text(tag, content, cls) {
  const el = document.createElement(tag);
  el.textContent = content;
  if (cls) { el.className = cls; }
  return el;
}

function link(label, action) {
  const a = text("a", label);
  a.href = "#";
  a.addEventListener("click", event => { event.preventDefault(); action(); });
  return a;
}

// One date format, always with its zone: "2024-05-01 08:30:00 UTC"; a date without a time
// of day stays a date ("2024-05-01 UTC").
function when(iso) {
  if (iso == null) { return "n/a"; }
  if (/^\d{4}-\d{2}-\d{2}$/.test(iso)) { return iso + " UTC"; }
  const t = new Date(iso);
  return isNaN(t) ? iso : t.toISOString().replace("T", " ").slice(0, 19) + " UTC";
}

// A full job id in a cell: selectable and copyable whole (the table keeps it while it polls).
function idCell(id) {
  const td = document.createElement("td");
  td.appendChild(text("code", id, "id"));
  return td;
}

// True while the user has a text selection inside `el`: its rows are then left alone.
function selecting(el) {
  const sel = window.getSelection();
  return sel && !sel.isCollapsed && sel.rangeCount > 0 && el.contains(sel.getRangeAt(0).commonAncestorContainer);
}

// Updates a table body in place: one row per item keyed by `key`, rebuilt only when what it
// shows (`signature`) changed, rows in the items' order. Nothing is redrawn while the user
// selects text in it.
function updateRows(tbody, items, key, signature, build) {
  if (selecting(tbody)) { return; }
  const wanted = new Set(items.map(key));
  for (const r of [...tbody.children]) { if (!wanted.has(r.id)) { r.remove(); } }
  let before = tbody.firstChild;
  for (const item of items) {
    const id = key(item), sig = signature(item);
    let r = document.getElementById(id);
    if (r && r.parentNode !== tbody) { r = null; }
    if (!r || r.dataset.sig !== sig) {
      const fresh = build(item);
      fresh.id = id; fresh.dataset.sig = sig;
      if (r) { r.replaceWith(fresh); } else { tbody.insertBefore(fresh, before); }
      r = fresh;
    } else if (r !== before) {
      tbody.insertBefore(r, before);
    }
    before = r.nextSibling;
  }
}

// Percent done as shown: 100 % only once the job succeeded (a diagnosis' simulations can all
// be done while it still writes its report).
function percentDone(job) {
  if (job.status === "succeeded") { return 100; }
  return Math.min(99, Math.floor(100 * job.progress.fraction));
}

function progressCell(job) {
  const cell = document.createElement("td");
  if (job.progress) {
    const pct = percentDone(job);
    const bar = document.createElement("span"); bar.className = "bar";
    const fill = document.createElement("span");
    fill.style.width = pct + "%";
    bar.appendChild(fill); cell.appendChild(bar);
    let label = " " + pct + " %";
    if (job.children) {
      // A sweep's progress is its points' (their simulated times are not summed here).
    } else if (job.kind === "diagnose") {
      label += " (" + Math.round(job.progress.simulated_time_s) + " / " + Math.round(job.progress.end_time_s) + " simulations";
    } else {
      label += " (t = " + job.progress.simulated_time_s.toFixed(2) + " / " + job.progress.end_time_s.toFixed(2) + " s simulated";
    }
    if (!job.children) {
      if (job.status === "running" && job.progress.eta_s != null) {
        label += etaText(job.progress.eta_s);
      }
      label += ")";
    }
    cell.appendChild(document.createTextNode(label));
  }
  if (job.children) {
    // A sweep fanned out into one child job per point, run by any worker.
    const c = job.children;
    let label = " " + c.succeeded + "/" + c.total + " points done";
    if (c.failed > 0) { label += ", " + c.failed + " failed"; }
    if (c.cancelled > 0) { label += ", " + c.cancelled + " cancelled"; }
    // A waiting sweep's ETA is its points' (measured point durations once one has finished).
    if (job.status === "waiting" && job.progress && job.progress.eta_s != null) {
      label += etaText(job.progress.eta_s);
    }
    cell.appendChild(text("span", label, "children"));
  }
  if (job.status === "queued" && !job.progress) {
    // No worker has it yet: no ETA would be honest.
    cell.appendChild(text("span", "waiting for a worker", "children"));
  }
  return cell;
}

function etaText(etaS) {
  const eta = Math.round(etaS);
  return eta > 0 ? ", ETA " + eta + " s" : ", finishing";
}

const ACTIVE = new Set(["queued", "running", "waiting"]);

// Whether the signed-in token may cancel this job: roles that submit jobs may cancel any,
// others the jobs they started (a test engineer's diagnosis).
function mayCancel(job) {
  return ACTIVE.has(job.status) && state.me !== null && (state.me.may.submit_jobs || job.submitted_by === state.me.name);
}

// Asks for a job's cancellation (the button waits for the answer).
function cancelButton(job, errorId) {
  const button = text("button", job.cancel_requested ? "cancelling" : "Cancel", "cancel-job");
  button.type = "button";
  button.disabled = job.cancel_requested;
  button.addEventListener("click", async () => {
    button.disabled = true;
    try { await api(job.links.cancel, { method: "POST" }); button.textContent = "cancelling"; } catch (e) {
      if (!(e instanceof Refused)) { button.disabled = false; document.getElementById(errorId).textContent = String(e); }
    }
  });
  return button;
}

// The tracks of a simulate job as a CSV file download (fetched with the token).
function downloadLink(job) {
  return link("download tracks (CSV)", async () => {
    try {
      const response = await fetch(job.links.tracks_csv, { headers: { "Authorization": "Bearer " + state.token } });
      if (!response.ok) { throw new Error(response.status + ": tracks"); }
      for (const old of document.querySelectorAll("a.tracks-download")) { URL.revokeObjectURL(old.href); old.remove(); }
      const a = document.createElement("a");
      a.href = URL.createObjectURL(await response.blob());
      a.download = "railwear-" + job.id + "-tracks.csv";
      a.className = "tracks-download";
      a.hidden = true;
      document.body.appendChild(a);
      a.click();
    } catch (e) { document.getElementById("error").textContent = String(e); }
  });
}

function jobSignature(job) {
  return JSON.stringify([job.status, job.progress, job.children, job.error, job.cancel_requested]);
}

function buildJobRow(job) {
  const row = document.createElement("tr");
  row.dataset.status = job.status;
  row.appendChild(idCell(job.id));
  row.appendChild(text("td", job.kind));
  row.appendChild(text("td", job.status, "status status-" + job.status));
  row.appendChild(progressCell(job));
  row.appendChild(text("td", when(job.created_at)));
  const links = document.createElement("td");
  links.appendChild(pageLink("page", "#/jobs/" + job.id, "job-page"));
  if (job.status === "succeeded" && job.kind === "simulate") { links.appendChild(downloadLink(job)); }
  else if (job.error) {
    links.appendChild(text("span", job.error));
  }
  if (mayCancel(job)) { links.appendChild(cancelButton(job, "error")); }
  row.appendChild(links);
  return row;
}

function renderJobs(page) {
  updateRows(document.getElementById("jobs"), page.items, j => "job-" + j.id, jobSignature, buildJobRow);
}

async function pollJobs(epoch) {
  try {
    // Submitted jobs only: a sweep's per-point child jobs show as its progress.
    const page = await api(jobsUrl());
    if (epoch !== state.epoch) { return; }
    jobList.next = page.next_cursor;
    renderJobs({ items: filterJobs(page.items) });
    renderJobPager();
    document.getElementById("error").textContent = "";
  } catch (e) { if (!(e instanceof Refused)) { document.getElementById("error").textContent = String(e); } }
}

// Ticks at 1, 2 or 5 times a power of ten, about `n` of them over [lo, hi].
function ticks(lo, hi, n) {
  const raw = (hi - lo) / n, mag = Math.pow(10, Math.floor(Math.log10(raw)));
  const step = [1, 2, 5, 10].map(f => f * mag).find(x => x >= raw);
  const out = [];
  for (let v = Math.ceil(lo / step) * step; v <= hi + step * 1e-9; v += step) { out.push(Number(v.toPrecision(12))); }
  return out;
}

// K_SL against rattle space, the axes fitted to the data: the curve with its swept points,
// the 0.9 and 0.8 conservative bands, this rail (with the interval over seeds when there is
// one) and the K_SL under a compared curve.
function curveSvg(report) {
  const pts = report.k_sl_curve;
  if (!pts || pts.length === 0) { return null; }
  const W = 640, H = 360, left = 64, right = 16, top = 16, bottom = 48;
  const life = report.service_life, band = life && life.interval;
  const compared = report.comparison && report.comparison.k_sl != null ? report.comparison.k_sl : null;
  const xs = pts.map(p => p[0]).concat([report.rattle_space]);
  const ys = pts.map(p => p[1]).concat(pts.map(p => 0.8 * p[1]));
  if (life) { ys.push(life.k_sl); }
  if (band) { ys.push(band.k_sl_low, band.k_sl_high); }
  if (compared != null) { ys.push(compared); }
  const pad = (lo, hi) => { const d = (hi - lo) || Math.abs(hi) || 1; return [lo - 0.05 * d, hi + 0.05 * d]; };
  const [x0, x1] = pad(Math.min(...xs), Math.max(...xs));
  const [y0, y1] = pad(Math.min(...ys), Math.max(...ys));
  const sx = x => left + (W - left - right) * (x - x0) / (x1 - x0);
  const sy = y => H - bottom - (H - top - bottom) * (y - y0) / (y1 - y0);
  const ns = "http://www.w3.org/2000/svg";
  const svg = document.createElementNS(ns, "svg");
  svg.setAttribute("width", W); svg.setAttribute("height", H); svg.setAttribute("id", "curve-plot");
  svg.setAttribute("viewBox", "0 0 " + W + " " + H);
  const el = (tag, attrs, cls) => {
    const e = document.createElementNS(ns, tag);
    for (const [k, v] of Object.entries(attrs)) { e.setAttribute(k, v); }
    if (cls) { e.setAttribute("class", cls); }
    svg.appendChild(e);
    return e;
  };
  const label = (x, y, s, anchor) => {
    const t = el("text", { x, y, "font-size": 13, "text-anchor": anchor || "start" });
    t.textContent = s;
    return t;
  };
  for (const t of ticks(x0, x1, 6)) {
    el("line", { x1: sx(t), y1: top, x2: sx(t), y2: H - bottom, stroke: "#eee" });
    label(sx(t), H - bottom + 16, t.toString(), "middle");
  }
  for (const t of ticks(y0, y1, 5)) {
    el("line", { x1: left, y1: sy(t), x2: W - right, y2: sy(t), stroke: "#eee" });
    label(left - 6, sy(t) + 4, t.toString(), "end");
  }
  el("line", { x1: left, y1: H - bottom, x2: W - right, y2: H - bottom, stroke: "#444" });
  el("line", { x1: left, y1: top, x2: left, y2: H - bottom, stroke: "#444" });
  label((left + W - right) / 2, H - 10, "rattle space k_rs (dimensionless)", "middle");
  const yTitle = label(16, (top + H - bottom) / 2, "K_SL", "middle");
  yTitle.setAttribute("transform", "rotate(-90 16 " + (top + H - bottom) / 2 + ")");
  const line = (factor, color, dash) => {
    const attrs = { points: pts.map(p => sx(p[0]) + "," + sy(factor * p[1])).join(" "), fill: "none", stroke: color, "stroke-width": 2 };
    if (dash) { attrs["stroke-dasharray"] = dash; }
    el("polyline", attrs);
  };
  line(0.9, "#6c757d", "6,4"); line(0.8, "#adb5bd", "2,3"); line(1.0, "#0a58ca", null);
  for (const p of pts) { el("circle", { cx: sx(p[0]), cy: sy(p[1]), r: 4, fill: "#0a58ca" }, "point"); }
  const legend = [["#0a58ca", null, "K_SL of the curve (swept points)"], ["#6c757d", "6,4", "0.9 x K_SL"], ["#adb5bd", "2,3", "0.8 x K_SL"]];
  if (life) {
    if (band) {
      el("line", { x1: sx(report.rattle_space), y1: sy(band.k_sl_low), x2: sx(report.rattle_space), y2: sy(band.k_sl_high),
        stroke: "#b02a37", "stroke-width": 2 }, "interval");
      for (const y of [band.k_sl_low, band.k_sl_high]) {
        el("line", { x1: sx(report.rattle_space) - 6, y1: sy(y), x2: sx(report.rattle_space) + 6, y2: sy(y), stroke: "#b02a37", "stroke-width": 2 });
      }
    }
    el("circle", { cx: sx(report.rattle_space), cy: sy(life.k_sl), r: 6, fill: "#b02a37" }, "rail");
    legend.push(["#b02a37", "dot", "this rail" + (band ? ", with the " + Math.round(100 * band.confidence) + " % interval over seeds" : "")]);
  }
  if (compared != null) {
    const cx = sx(report.rattle_space) + 14, cy = sy(compared);
    el("path", { d: "M" + cx + " " + (cy - 7) + " l7 7 l-7 7 l-7 -7 z", fill: "#fd7e14" }, "compared");
    legend.push(["#fd7e14", "dot", "K_SL under curve " + report.comparison.curve_id]);
  }
  let ly = top + 10;
  const lx = W - right - 290;
  el("rect", { x: lx - 8, y: top, width: 290, height: 18 * legend.length + 8, fill: "white", stroke: "#ccc" }, "legend");
  for (const [color, dash, name] of legend) {
    if (dash === "dot") { el("circle", { cx: lx + 11, cy: ly, r: 5, fill: color }); }
    else {
      const attrs = { x1: lx, y1: ly, x2: lx + 22, y2: ly, stroke: color, "stroke-width": 2 };
      if (dash) { attrs["stroke-dasharray"] = dash; }
      el("line", attrs);
    }
    label(lx + 30, ly + 4, name).setAttribute("class", "legend-entry");
    ly += 18;
  }
  return svg;
}

async function loadReport() {
  const serial = document.getElementById("serial").value.trim();
  const out = document.getElementById("report");
  const plot = document.getElementById("curve");
  const epoch = state.epoch;
  out.replaceChildren(); plot.replaceChildren();
  if (!serial) { return; }
  try {
    const compare = document.getElementById("compare").value.trim();
    const r = await api("/v1/rails/" + encodeURIComponent(serial) + "/report" +
      (compare ? "?compare=" + encodeURIComponent(compare) : ""));
    if (epoch !== state.epoch) { return; }
    out.appendChild(text("div", "Rail " + r.serial + ": rattle space k_rs = " + r.rattle_space.toFixed(4) +
      " (measured " + when(r.measurement.measured_at) + " by " + r.measurement.measured_by + " at " + r.measurement.location + ")"));
    if (r.service_life) {
      const s = r.service_life;
      const life = text("div", "K_SL = " + s.k_sl.toFixed(3) + "; service life " + s.penalized_life_h.toFixed(0) +
        " h of " + s.design_life_h.toFixed(0) + " h design", "status-succeeded");
      life.id = "report-life";
      out.appendChild(life);
      const band = s.interval;
      const spread = text("div", band
        ? Math.round(100 * band.confidence) + " % interval over " + band.seeds + " seeds: K_SL " + band.k_sl_low.toFixed(4) +
          " to " + band.k_sl_high.toFixed(4) + ", service life " + band.penalized_life_low_h.toFixed(0) + " to " +
          band.penalized_life_high_h.toFixed(0) + " h. " + s.uncertainty
        : "No interval: " + s.uncertainty, "interval");
      spread.id = "report-interval";
      out.appendChild(spread);
      out.appendChild(text("div", "Conservative bands (Figure 6.68): 0.9 x K_SL = " + s.k_sl_band_90.toFixed(3) +
        " (" + s.penalized_life_band_90_h.toFixed(0) + " h), 0.8 x K_SL = " + s.k_sl_band_80.toFixed(3) + " (" +
        s.penalized_life_band_80_h.toFixed(0) + " h)."));
    }
    if (r.curve) {
      const c = r.curve, f = c.fidelity;
      const used = text("div", "Curve used: " + c.id + " (" + c.curve_key + ", version " + c.version + "; " + f.points +
        " points, " + (f.duration_per_point_s == null ? "duration not recorded" : f.duration_per_point_s + " s") + " per point, " +
        f.seeds + " seed" + (f.seeds === 1 ? "" : "s") + " per point; published " + when(c.published_at) + ")");
      used.id = "report-curve";
      out.appendChild(used);
    }
    if (r.missing_curve) { out.appendChild(text("div", r.missing_curve.detail, "status-cancelled")); }
    if (r.comparison) {
      out.appendChild(comparisonLine(r.comparison));
      if (r.curve) {
        const other = await api("/v1/curves/" + encodeURIComponent(r.comparison.curve_id));
        if (epoch !== state.epoch) { return; }
        const warning = fidelityWarning(r.curve, other);
        if (warning) { out.appendChild(warning); }
      }
    }
    const svg = curveSvg(r);
    if (svg) { plot.appendChild(svg); }
  } catch (e) { if (!(e instanceof Refused)) { out.appendChild(text("div", String(e), "status-failed")); } }
}

// A compared curve with less simulation behind it than the report's: fewer points, shorter
// runs or fewer seeds make its K_SL less certain, and the page says so.
function fidelityWarning(used, other) {
  const a = used.fidelity, b = other.fidelity, lower = [];
  if (b.points < a.points) { lower.push(b.points + " points against " + a.points); }
  if (b.duration_per_point_s != null && a.duration_per_point_s != null && b.duration_per_point_s < a.duration_per_point_s) {
    lower.push(b.duration_per_point_s + " s per point against " + a.duration_per_point_s + " s");
  }
  if (b.seeds < a.seeds) { lower.push(b.seeds + " seed" + (b.seeds === 1 ? "" : "s") + " per point against " + a.seeds); }
  if (lower.length === 0) { return null; }
  const div = text("div", "Curve " + other.id + " has less simulation behind it than curve " + used.id + " (" +
    lower.join(", ") + "): its K_SL is less certain" + (b.seeds < 2 ? ", and with one seed it has no interval" : "") + ".",
    "status-cancelled");
  div.id = "report-fidelity-warning";
  return div;
}

// K_SL and the penalized life under another stored curve (`?compare=<curve id>`).
function comparisonLine(c) {
  const line = c.k_sl == null ? c.detail :
    "Under curve " + c.curve_id + " (" + c.curve_key + ", version " + c.version +
    (c.published ? ", published" : ", not published") + "): K_SL = " + c.k_sl.toFixed(3) +
    ", service life " + c.penalized_life_h.toFixed(0) + " h" +
    (c.k_sl_ratio == null ? "" : "; " + c.k_sl_ratio.toFixed(3) + " x the report's K_SL");
  const div = text("div", line, c.k_sl == null ? "status-cancelled" : "");
  div.id = "report-comparison";
  return div;
}

// ---- Diagnoses (issue 15): campaigns, diagnose jobs, their reports ----

// Campaign ids whose "Start diagnosis" request is under way (their buttons wait).
// `jobs`: the diagnose jobs seen, by id.
const diag = { may: false, campaigns: new Map(), jobs: new Map(), shown: null, started: null, starting: new Set() };

// Numbers with their units. Held-out errors are RMS standardized errors: multiples of each
// observation's standard uncertainty (sigma).
const fmt = {
  num: (x, digits) => (x == null || !isFinite(x)) ? "n/a" :
    (Math.abs(x) !== 0 && (Math.abs(x) >= 1e4 || Math.abs(x) < 1e-3)) ? x.toExponential(digits - 1) : x.toPrecision(digits),
  sigma: x => fmt.num(x, 3) + " \u03c3",
  percent: x => (x == null || !isFinite(x)) ? "n/a" : (100 * x).toFixed(1) + " %",
  bytes: n => n >= 1048576 ? (n / 1048576).toFixed(1) + " MiB" : n >= 1024 ? (n / 1024).toFixed(1) + " KiB" : n + " B",
  // A dimensionless value (unit "1" or none) shows no unit.
  withUnit: (x, unit) => fmt.num(x, 3) + (unit && unit !== "1" ? " " + unit : ""),
  // p-values: three decimals, in scientific notation below 1e-3.
  p: x => (x == null || !isFinite(x)) ? "n/a" : x === 0 ? "< 1e-300" : x < 1e-3 ? x.toExponential(1) : x.toFixed(3),
  count: x => (x == null || !isFinite(x)) ? "n/a" : String(Math.round(x)),
};

// Why a candidate does not explain the gap, by the rule of docs/results/diagnosis.md: a held-out gain
// above 2 nats, residuals consistent with noise (p >= alpha) and at least 50 % of the excess
// chi-square removed. The report carries alpha; the two other thresholds are the rule's.
function whyNot(e, alpha) {
  const reasons = [];
  if (!(e.held_out_gain > 2)) { reasons.push("held-out gain " + fmt.num(e.held_out_gain, 3) + " nats, not above 2"); }
  if (!(e.residual_p_value >= alpha)) { reasons.push("residual p " + fmt.p(e.residual_p_value) + " < " + alpha); }
  if (!(e.explained_share >= 0.5)) { reasons.push("removes " + fmt.percent(e.explained_share) + " of the excess, under 50 %"); }
  return reasons.length > 0 ? "no: " + reasons.join("; ") : "no";
}

// A table with a caption (which interval level it shows).
function captioned(t, caption) {
  t.insertBefore(text("caption", caption), t.firstChild);
  return t;
}

// A place for one of the report's figures, beside the table it illustrates.
function figureSlot(name) {
  const div = document.createElement("div");
  div.className = "plots";
  div.dataset.slot = name;
  return div;
}

function diagnosisOptions() {
  const body = {};
  const number = (id, key) => {
    const v = document.getElementById(id).value.trim();
    if (v !== "") { body[key] = Number(v); }
  };
  number("opt-window", "window_s");
  number("opt-settle", "settle_s");
  number("opt-grid", "grid_points");
  const effects = document.getElementById("opt-effects").value.trim();
  if (effects !== "") { body.effects = effects.split(",").map(e => e.trim()).filter(e => e !== ""); }
  return body;
}

// One job per click: the button is disabled until the service answered.
async function startDiagnosis(campaign) {
  if (diag.starting.has(campaign.id)) { return; }
  const error = document.getElementById("diagnose-error");
  const epoch = state.epoch;
  error.textContent = "";
  diag.starting.add(campaign.id);
  renderCampaigns([...diag.campaigns.values()]);
  try {
    const job = await api(campaign.links.self + "/diagnoses", {
      method: "POST",
      headers: { "Content-Type": "application/json" },
      body: JSON.stringify(diagnosisOptions()),
    });
    // Show this diagnosis' report once it has one.
    diag.started = job.id;
    diag.shown = null;
    showDiagnosisProgress(job);
    diag.jobs.set(job.id, job);
    renderDiagnoses([...diag.jobs.values()].sort((x, y) => x.created_at < y.created_at ? 1 : -1));
  } catch (e) {
    if (!(e instanceof Refused)) { error.textContent = String(e); }
  } finally {
    if (epoch === state.epoch) {
      diag.starting.delete(campaign.id);
      renderCampaigns([...diag.campaigns.values()]);
    }
  }
}

function buildCampaignRow(c) {
  const row = document.createElement("tr");
  row.appendChild(text("td", c.name));
  row.appendChild(text("td", when(c.created_at) + " by " + c.created_by));
  const n = c.counts;
  row.appendChild(text("td", n.tests + " / " + n.specimens + " / " + n.increments + " / " + n.accelerometer_records));
  row.appendChild(text("td", fmt.bytes(c.content_bytes)));
  const action = document.createElement("td");
  if (diag.may) {
    const button = text("button", "Start diagnosis", "start-diagnosis");
    button.type = "button";
    button.disabled = diag.starting.has(c.id);
    button.addEventListener("click", () => startDiagnosis(c));
    action.appendChild(button);
  }
  row.appendChild(action);
  return row;
}

function renderCampaigns(items) {
  diag.campaigns.clear();
  for (const c of items) { diag.campaigns.set(c.id, c); }
  updateRows(document.getElementById("campaigns"), items, c => "campaign-" + c.id,
    c => JSON.stringify([c.name, diag.may, diag.starting.has(c.id)]), buildCampaignRow);
}

function buildDiagnosisRow(job) {
  const row = document.createElement("tr");
  row.dataset.status = job.status;
  row.appendChild(idCell(job.id));
  const campaign = diag.campaigns.get(job.params.campaign_id);
  row.appendChild(text("td", campaign ? campaign.name : job.params.campaign_id));
  row.appendChild(text("td", job.status, "status status-" + job.status));
  row.appendChild(progressCell(job));
  row.appendChild(text("td", when(job.created_at) + " by " + job.submitted_by));
  const links = document.createElement("td");
  if (job.status === "succeeded") {
    links.appendChild(pageLink("report", "#/diagnoses/" + job.id, "report"));
  } else if (job.error) {
    links.appendChild(text("span", job.error));
  }
  if (mayCancel(job)) { links.appendChild(cancelButton(job, "diagnose-error")); }
  row.appendChild(links);
  return row;
}

function renderDiagnoses(jobs) {
  updateRows(document.getElementById("diagnoses"), jobs, j => "diagnosis-" + j.id,
    j => JSON.stringify([jobSignature(j), diag.campaigns.has(j.params.campaign_id)]), buildDiagnosisRow);
  for (const job of jobs) {
    if (job.id !== diag.started) { continue; }
    // The panel follows the job's row until its report is shown.
    if (job.status === "succeeded") { diag.started = null; showDiagnosis(job); }
    else {
      if (!ACTIVE.has(job.status)) { diag.started = null; }
      showDiagnosisProgress(job);
    }
  }
}

function showDiagnosisProgress(job) {
  const out = document.getElementById("diagnosis");
  const line = job.error ? "Diagnosis " + job.id + " " + job.status + ": " + job.error
    : "Diagnosis " + job.id + " " + job.status + "; its report shows here when it succeeds.";
  if (out.dataset.job === job.id && out.dataset.status === job.status && out.textContent === line) { return; }
  out.replaceChildren();
  out.dataset.job = job.id;
  out.dataset.status = job.status;
  delete out.dataset.verdict;
  out.appendChild(text("div", line, "status-" + job.status));
}

function table(headers, rows) {
  const t = document.createElement("table");
  const head = document.createElement("tr");
  for (const h of headers) { head.appendChild(text("th", h)); }
  const thead = document.createElement("thead"); thead.appendChild(head); t.appendChild(thead);
  const tbody = document.createElement("tbody");
  for (const r of rows) { tbody.appendChild(r); }
  t.appendChild(tbody);
  return t;
}

function row(cells, cls) {
  const r = document.createElement("tr");
  if (cls) { r.className = cls; }
  for (const c of cells) { r.appendChild(text("td", c)); }
  return r;
}

function interval(pair, unit) {
  return pair ? "[" + fmt.num(pair[0], 3) + ", " + fmt.num(pair[1], 3) + "]" + (unit ? " " + unit : "") : "n/a";
}

async function showDiagnosis(job) {
  if (diag.shown === job.id) { return; }
  diag.shown = job.id;
  const epoch = state.epoch;
  const out = document.getElementById("diagnosis");
  out.replaceChildren();
  out.dataset.job = job.id;
  out.dataset.status = job.status;
  delete out.dataset.verdict;
  try {
    const result = await api(job.links.result);
    if (epoch !== state.epoch) { return; }
    const r = result.summary;
    out.appendChild(text("h3", "Diagnosis of " + r.campaign + " (job " + job.id + ", started by " + job.submitted_by + ")"));
    const verdict = text("div", "", "verdict-line");
    verdict.appendChild(document.createTextNode("Verdict: "));
    verdict.appendChild(text("strong", r.verdict, "verdict"));
    verdict.appendChild(document.createTextNode(". " + r.summary));
    out.appendChild(verdict);

    if (r.best_effect) {
      const b = r.best_effect;
      out.appendChild(text("h4", (r.verdict === "partly_explained"
        ? "Leading candidate (partly explains the gap): " : "Best effect: ") + b.name));
      if (r.partly_explained) {
        const p = r.partly_explained;
        out.appendChild(text("div", "Not explained in full: " + p.reasons.join("; ") + ". It cannot predict " +
          p.cannot_predict + " (held-out RMS error " + fmt.sigma(p.cannot_predict_error[0]) + " nominal, " +
          fmt.sigma(p.cannot_predict_error[1]) + " with it).", "partly-explained"));
        const unpredicted = p.unpredicted || [];
        if (unpredicted.length > 0) {
          out.appendChild(text("div", "Withheld groups it does not predict within their noise: " +
            unpredicted.map(g => g.group + " (held-out error " + fmt.sigma(g.after) + " against a bound of " +
              fmt.sigma(g.bound) + ")").join("; ") + ".", "partly-explained"));
        }
      }
      out.appendChild(text("div", "Held-out RMS standardized error: " + fmt.sigma(b.held_out_error_before) +
        " before, " + fmt.sigma(b.held_out_error_after) + " after; the gap shrinks by " + fmt.percent(b.shrink) +
        " (90 % interval " + fmt.percent(b.shrink_interval[0]) + " to " + fmt.percent(b.shrink_interval[1]) +
        "); lack-of-fit p-value of what is left " + fmt.p(b.residual_p_value) + ".", "best-effect"));
      // A parameter the data do not identify shows no point value; an interval that reaches a
      // physical bound says so.
      const params = b.parameters.map(p => row([
        p.effect, p.name,
        p.fitted && p.identified === false ? "not identified by the data" : fmt.withUnit(p.value, p.unit),
        (p.fitted ? interval(p.interval, p.unit) : "held at default") +
          (p.bounds_reached && p.bounds_reached.length > 0 ? " (reaches its " + p.bounds_reached.join(" and ") + " bound)" : ""),
        interval(p.bounds, p.unit),
      ]));
      const paramTable = captioned(table(["Effect", "Parameter", "Value", "Interval", "Physical bounds"], params),
        "Fitted parameters; intervals at 95 %");
      paramTable.id = "diagnosis-parameters";
      out.appendChild(paramTable);
      out.appendChild(figureSlot("before_after.svg"));
    } else {
      out.appendChild(text("div", "No effect named. Nominal model: held-out RMS standardized error " +
        fmt.sigma(r.nominal.held_out_error) + ", chi-square " + fmt.num(r.nominal.chi2, 3) + " on " +
        fmt.count(r.nominal.dof) + " degrees of freedom (p = " + fmt.p(r.nominal.p_value) + ").", "best-effect"));
      out.appendChild(figureSlot("before_after.svg"));
    }

    out.appendChild(text("h4", "Ranking (held out: " + r.held_out + ")"));
    const runnersUp = new Set(r.indistinguishable);
    const ranking = r.ranking.concat(r.pairs).map((e, i) => {
      const mark = e.name === (r.best_effect && r.best_effect.name) ? "best"
        : runnersUp.has(e.name) ? "indistinguishable from the best" : "";
      const tr = row([String(i + 1), e.name, fmt.num(e.held_out_gain, 3) + " nats",
        e.held_out_gain_interval ? interval(e.held_out_gain_interval, "nats") : "n/a", fmt.sigma(e.held_out_error),
        fmt.percent(e.explained_share), fmt.p(e.residual_p_value), fmt.percent(e.p_first),
        e.explains ? "yes" : whyNot(e, r.alpha), mark], runnersUp.has(e.name) ? "indistinguishable" : "");
      tr.dataset.effect = e.name;
      return tr;
    });
    const rankTable = captioned(table(["#", "Effect", "Held-out log-likelihood gain", "Gain interval",
      "Held-out RMS error", "Excess chi-square removed", "Lack-of-fit p", "P(first), bootstrap", "Explains", ""], ranking),
      "Candidates; gain intervals at 90 % (bootstrap over held-out groups)");
    rankTable.id = "diagnosis-ranking";
    out.appendChild(rankTable);
    out.appendChild(figureSlot("ranking.svg"));

    // Held-out predictions: what the nominal model and the best-ranked effect, each fitted
    // without the observation's group, say each measured mass should be.
    if (r.held_out_predictions && r.held_out_predictions.length > 0) {
      out.appendChild(text("h4", "Held-out predictions per test"));
      const predictions = r.held_out_predictions.map(h => row([h.test, String(h.increment), h.quantity,
        fmt.num(h.measured_mg, 3) + " \u00b1 " + fmt.num(h.uncertainty_mg, 2) + " mg", fmt.num(h.nominal_mg, 3) + " mg",
        h.effect + " (" + fmt.num(h.magnitude, 3) + ")", fmt.num(h.with_effect_mg, 3) + " mg"]));
      const predictionTable = captioned(table(["Test", "Increment", "Quantity", "Measured (standard uncertainty)",
        "Nominal model", "Best-ranked effect (magnitude)", "With it"], predictions),
        "Each prediction fitted without its own group (held out: " + r.held_out + ")");
      predictionTable.id = "diagnosis-predictions";
      out.appendChild(predictionTable);
    }

    // The next tests: repeats of the tests the leading candidate cannot be confirmed on held
    // out ("What changes" says so), then what would best tell it from its rivals, cheapest
    // decisive first (expected log-likelihood ratio above ln 20 against every rival).
    const next = r.next_tests || [];
    if (next.length > 0) {
      out.appendChild(text("h4", "Next tests: to tell " + next[0].separates[0] + " from " +
        next[0].separates.slice(1).join(", ")));
      const proposals = next.map(t => {
        const tr = row([t.test.id, t.case, t.change,
          t.increments + " \u00d7 " + fmt.num(t.increment_duration_s / 3600, 3) + " h \u00d7 " + t.repeats,
          t.accelerometers ? "on" : "off", fmt.num(t.cost_h, 3) + " h",
          fmt.num(t.separation_nats, 3) + " nats" + (t.decisive ? " (decisive)" : ""),
          t.decides.join(" ")], t.decisive ? "decisive" : "");
        tr.dataset.test = t.test.id;
        return tr;
      });
      const nextTable = captioned(table(["Test", "Case", "What changes", "Increments \u00d7 length \u00d7 specimens",
        "Records", "Test hours", "Expected separation", "What each outcome decides"], proposals),
        "Each test's smallest expected log-likelihood ratio between the leading candidate and a rival");
      nextTable.id = "diagnosis-next-tests";
      out.appendChild(nextTable);
    } else {
      out.appendChild(text("div", "Next tests: none (nothing left to separate).", "next-tests-none"));
    }

    out.appendChild(text("h4", "Where the nominal model misses (Holm-adjusted p < 0.05)"));
    const flagged = r.where.groups.filter(g => g.flagged);
    if (flagged.length === 0) {
      out.appendChild(text("div", "No group flagged.", "where-none"));
    } else {
      const groups = flagged.map(g => {
        const unit = g.by === "frequency_band" ? "dB (measured / model)" : "\u03c3";
        const tr = row([g.by, g.label, fmt.num(g.mean_residual, 3) + " " + unit, fmt.num(g.z, 3),
          fmt.p(g.p_adjusted), fmt.num(g.observations, 3)]);
        tr.className = "flagged";
        return tr;
      });
      const whereTable = table(["By", "Group", "Mean residual", "Bias score z", "Adjusted p", "Observations (weighted)"], groups);
      whereTable.id = "diagnosis-where";
      out.appendChild(whereTable);
    }
    out.appendChild(figureSlot("residuals.svg"));

    const budget = r.where.energy_budget;
    if (budget && budget.tests.length > 0) {
      out.appendChild(text("h4", "Energy budget of the nominal model (work by kind, J) and the coefficient each wear mechanism needs"));
      const work = [];
      for (const t of budget.tests) {
        for (const c of t.contacts) {
          work.push(row([t.test, c.contact, fmt.num(t.drive_j, 3) + " J", fmt.num(c.friction_j, 3) + " J", fmt.num(c.damping_j, 3) + " J",
            fmt.num(c.damping_to_friction, 3), fmt.percent(c.share_above_yield),
            fmt.num(c.lumped_archard_mm3, 3) + " / " + fmt.num(c.local_archard_mm3, 3) + " mm\u00b3"]));
        }
      }
      const workTable = table(["Test", "Contact", "Drive work (test)", "Friction work", "Impact damping work",
        "Damping / friction", "Sliding above Sy", "Archard wear: lumped / local pressure"], work);
      workTable.id = "diagnosis-budget";
      out.appendChild(workTable);
      const needed = [];
      for (const t of budget.tests) {
        for (const n of t.needed) {
          const tr = row([t.test, n.component, n.mechanism, n.value == null ? "no driver" : fmt.withUnit(n.value, n.unit),
            interval(n.range, n.unit), n.verdict]);
          if (n.verdict === "within") { tr.className = "indistinguishable"; }
          needed.push(tr);
        }
      }
      const neededTable = table(["Test", "Component", "Mechanism", "Needed for the measured wear", "Literature range", ""], needed);
      neededTable.id = "diagnosis-budget-needed";
      out.appendChild(neededTable);
    }
    out.appendChild(figureSlot("energy_budget.svg"));

    // Each figure beside the table it illustrates; any other at the end.
    const rest = figureSlot("");
    out.appendChild(rest);
    for (const plot of result.plots) {
      const slot = [...out.querySelectorAll("div[data-slot]")].find(d => d.dataset.slot === plot.name) || rest;
      await showPlots([plot], slot, epoch);
      if (epoch !== state.epoch) { return; }
    }
    out.dataset.verdict = r.verdict;
  } catch (e) {
    if (e instanceof Refused || epoch !== state.epoch) { return; }
    diag.shown = null;
    out.appendChild(text("div", String(e), "status-failed"));
  }
}

// ---- Pages with URLs: #/rails, #/rails/<serial>?compare=<curve id>, #/curves, #/jobs?kind=&status=&by=,
// #/jobs/<id>, #/campaigns, #/diagnoses/<id>. Links can be bookmarked and shared; the token is never
// part of them.

function parseRoute() {
  const hash = location.hash.startsWith("#/") ? location.hash.slice(2) : "";
  const [path, query] = hash.split("?");
  const parts = path.split("/").filter(p => p !== "").map(p => decodeURIComponent(p));
  return { parts, params: new URLSearchParams(query || "") };
}

// Goes to a page; going to the page already shown shows it again (a report opened before a
// sign-out opens after the next sign-in).
function go(hash) {
  if (location.hash === hash) { route(); } else { location.hash = hash; }
}

function pageLink(label, hash, cls) {
  const a = text("a", label, cls);
  a.href = hash;
  a.addEventListener("click", event => { event.preventDefault(); go(hash); });
  return a;
}

function showView(view) {
  for (const s of document.querySelectorAll("section[data-view]")) { s.hidden = s.dataset.view !== view; }
  const tab = view === "job" ? "jobs" : view === "rail" ? "rails" : view;
  for (const a of document.querySelectorAll("#nav a")) { a.classList.toggle("active", a.dataset.nav === tab); }
}

// The page a role starts on when the address names none.
function homeOf(me) {
  return me.role === "planner" ? "rails" : me.role === "test_engineer" ? "campaigns" : "jobs";
}

function route() {
  if (state.me === null) { showView(null); return; }
  const { parts, params } = parseRoute();
  const page = parts[0] || homeOf(state.me);
  state.route = { page, id: parts[1] || null, params };
  const epoch = state.epoch;
  if (page === "jobs" && parts[1]) { showView("job"); loadJobPage(parts[1], epoch); }
  else if (page === "jobs") { showView("jobs"); setJobFilters(params); pollJobs(epoch); }
  else if (page === "rails" && parts[1]) { showView("rail"); loadRail(parts[1], params.get("compare") || "", epoch); }
  else if (page === "rails") { showView("rails"); loadRails(epoch); }
  else if (page === "curves") { showView("curves"); loadCurves(epoch); }
  else if (page === "diagnoses" && parts[1]) { showView("campaigns"); openDiagnosis(parts[1], epoch); }
  else { showView("campaigns"); }
}

// ---- Jobs: filters and pages ----

// Cursors of the pages seen (index 0: the newest); `next`: the older page's.
const jobList = { cursors: [null], index: 0, next: null, key: "" };

function setJobFilters(params) {
  const key = params.toString();
  document.getElementById("filter-kind").value = params.get("kind") || "";
  document.getElementById("filter-status").value = params.get("status") || "";
  document.getElementById("filter-submitter").value = params.get("by") || "";
  if (key !== jobList.key) { jobList.key = key; jobList.cursors = [null]; jobList.index = 0; jobList.next = null; }
}

function jobsUrl() {
  const params = state.route.params;
  let url = "/v1/jobs?limit=100&top_level=true";
  if (params.get("status")) { url += "&status=" + encodeURIComponent(params.get("status")); }
  const cursor = jobList.cursors[jobList.index];
  if (cursor) { url += "&cursor=" + encodeURIComponent(cursor); }
  return url;
}

// The list filters status; kind and submitter are matched within each page of 100 jobs (the
// job list has no kind or submitter filter).
function filterJobs(items) {
  const params = state.route.params;
  const kind = params.get("kind"), by = params.get("by");
  return items.filter(j => (!kind || j.kind === kind) && (!by || j.submitted_by === by));
}

function renderJobPager() {
  document.getElementById("jobs-newer").disabled = jobList.index === 0;
  document.getElementById("jobs-older").disabled = !jobList.next;
  document.getElementById("jobs-page").textContent = "page " + (jobList.index + 1);
  const params = state.route.params;
  document.getElementById("jobs-note").textContent = params.get("kind") || params.get("by")
    ? "kind and submitter are matched within each page of 100 jobs" : "";
}

// ---- A job's page: parameters, status, attempts, duration, cancel, figures, downloads ----

function seconds(s) {
  if (s == null || !isFinite(s)) { return "n/a"; }
  if (s < 60) { return s.toFixed(1) + " s"; }
  const m = Math.floor(s / 60);
  if (m < 60) { return m + " min " + Math.round(s - 60 * m) + " s"; }
  return Math.floor(m / 60) + " h " + (m % 60) + " min";
}

function flatten(value, prefix, out) {
  for (const key of Object.keys(value)) {
    const v = value[key], name = prefix ? prefix + "." + key : key;
    if (v !== null && typeof v === "object" && !Array.isArray(v)) { flatten(v, name, out); }
    else { out.push([name, typeof v === "string" ? v : JSON.stringify(v)]); }
  }
  return out;
}

function keyValueTable(pairs, id) {
  const t = table(["", ""], pairs.map(([k, v]) => row([k, v])));
  t.id = id; t.className = "facts";
  t.querySelector("thead").remove();
  return t;
}

const jobPage = { id: null, status: null };

async function loadJobPage(id, epoch) {
  const out = document.getElementById("job-page");
  if (selecting(out)) { return; }
  try {
    const job = await api("/v1/jobs/" + encodeURIComponent(id));
    const attempts = await api(job.links.attempts);
    if (epoch !== state.epoch || !state.route || state.route.id !== id) { return; }
    const fresh = jobPage.id !== id || jobPage.status !== job.status;
    jobPage.id = id; jobPage.status = job.status;
    const page = document.createElement("div");
    page.dataset.job = job.id; page.dataset.status = job.status;
    const title = text("h2", job.kind + " job ");
    title.appendChild(text("code", job.id, "id"));
    page.appendChild(title);
    const status = text("div", "", "job-status");
    status.appendChild(text("strong", job.status, "status status-" + job.status));
    const progress = progressCell(job);
    while (progress.firstChild) { status.appendChild(progress.firstChild); }
    if (mayCancel(job)) { status.appendChild(cancelButton(job, "error")); }
    page.appendChild(status);
    const end = job.finished_at ? new Date(job.finished_at) : new Date();
    const duration = job.started_at ? (end - new Date(job.started_at)) / 1000 : null;
    const facts = [
      ["Submitted by", job.submitted_by], ["Created", when(job.created_at)],
      ["Started", job.started_at ? when(job.started_at) : "not yet"],
      ["Finished", job.finished_at ? when(job.finished_at) : "not yet"],
      ["Duration (wall clock)", duration == null ? "n/a" : seconds(duration) + (job.finished_at ? "" : " so far")],
      ["Attempts", String(job.attempt)], ["Seed", String(job.seed)], ["Code version", job.code_version],
    ];
    if (job.worker) { facts.push(["Worker", job.worker]); }
    if (job.curve_key) { facts.push(["Curve key", job.curve_key]); }
    if (job.error) { facts.push(["Error", job.error]); }
    page.appendChild(keyValueTable(facts, "job-facts"));
    page.appendChild(text("h3", "Parameters"));
    page.appendChild(keyValueTable(flatten(job.params, "", []), "job-params"));
    if (attempts.length > 0) {
      page.appendChild(text("h3", "Attempts"));
      const rows = attempts.map(a => row([String(a.attempt), a.worker, when(a.started_at),
        a.ended_at ? when(a.ended_at) : "running", a.outcome]));
      const t = table(["#", "Worker", "Started", "Ended", "Outcome"], rows);
      t.id = "job-attempts";
      page.appendChild(t);
    }
    if (job.status === "succeeded" && !fresh) { return; }
    out.replaceChildren(page);
    if (job.kind === "diagnose") { page.appendChild(pageLink("the diagnosis report", "#/diagnoses/" + job.id)); }
    if (job.status !== "succeeded") { return; }
    const result = await api(job.links.result);
    if (epoch !== state.epoch || jobPage.id !== id) { return; }
    page.appendChild(text("h3", "Downloads"));
    const downloads = document.createElement("p");
    if (job.kind === "simulate") { downloads.appendChild(downloadLink(job)); }
    const json = document.createElement("a");
    json.href = URL.createObjectURL(new Blob([JSON.stringify(result, null, 2)], { type: "application/json" }));
    json.download = "railwear-" + job.id + "-result.json";
    json.textContent = "result (JSON)";
    downloads.appendChild(json);
    page.appendChild(downloads);
    if (result.plots.length > 0) {
      page.appendChild(text("h3", "Figures"));
      const plots = document.createElement("div");
      plots.className = "plots";
      page.appendChild(plots);
      await showPlots(result.plots, plots, epoch);
    }
  } catch (e) {
    if (!(e instanceof Refused) && epoch === state.epoch) { out.replaceChildren(text("div", String(e), "status-failed")); }
  }
}

// Figures fetched with the token and shown as images (an <img> runs no script).
async function showPlots(list, into, epoch) {
  for (const plot of list) {
    const response = await fetch(plot.url, { headers: { "Authorization": "Bearer " + state.token } });
    if (epoch !== state.epoch) { return; }
    if (!response.ok) { into.appendChild(text("div", plot.name + ": " + response.status, "status-failed")); continue; }
    const figure = document.createElement("figure");
    const img = document.createElement("img");
    img.alt = plot.name;
    img.dataset.plot = plot.name;
    img.src = URL.createObjectURL(await response.blob());
    figure.appendChild(img);
    figure.appendChild(text("figcaption", plot.name));
    into.appendChild(figure);
  }
}

// ---- Rails ----

async function loadRails(epoch) {
  try {
    const page = await api("/v1/rails?limit=100");
    if (epoch !== state.epoch) { return; }
    updateRows(document.getElementById("rails"), page.items, r => "rail-row-" + r.serial,
      r => JSON.stringify([r.measurements]), r => {
        const tr = document.createElement("tr");
        const cell = document.createElement("td");
        cell.appendChild(pageLink(r.serial, "#/rails/" + encodeURIComponent(r.serial)));
        tr.appendChild(cell);
        tr.appendChild(text("td", when(r.registered_at)));
        tr.appendChild(text("td", String(r.measurements)));
        return tr;
      });
  } catch (e) { if (!(e instanceof Refused)) { document.getElementById("error").textContent = String(e); } }
}

async function loadRail(serial, compare, epoch) {
  document.getElementById("serial").value = serial;
  document.getElementById("compare").value = compare;
  document.getElementById("rail-title").textContent = "Rail " + serial;
  const history = document.getElementById("measurements");
  history.replaceChildren();
  await loadReport();
  try {
    const page = await api("/v1/rails/" + encodeURIComponent(serial) + "/measurements?limit=100");
    if (epoch !== state.epoch) { return; }
    for (const m of page.items) {
      history.appendChild(row([when(m.measured_at), m.measured_by, m.location, m.rattle_space.toFixed(4),
        when(m.recorded_at) + " by " + m.recorded_by]));
    }
  } catch (e) { if (!(e instanceof Refused)) { history.appendChild(row([String(e)], "status-failed")); } }
}

// ---- Curves ----

function fidelityText(f) {
  return f.points + " points, " + (f.duration_per_point_s == null ? "duration not recorded"
    : f.duration_per_point_s + " s per point") + ", " + f.seeds + " seed" + (f.seeds === 1 ? "" : "s");
}

async function publishCurve(c, force) {
  const error = document.getElementById("curves-error");
  error.replaceChildren();
  const epoch = state.epoch;
  try {
    await api(c.links.publish, { method: "POST", headers: { "Content-Type": "application/json" },
      body: JSON.stringify({ force }) });
  } catch (e) {
    if (e instanceof Refused) { return; }
    error.appendChild(document.createTextNode(String(e) + " "));
    if (!force && /force/.test(String(e))) {
      const again = text("button", "Publish anyway", "publish-force");
      again.type = "button";
      again.addEventListener("click", () => publishCurve(c, true));
      error.appendChild(again);
    }
  }
  if (epoch === state.epoch) { loadCurves(epoch); }
}

async function loadCurves(epoch) {
  try {
    const page = await api("/v1/curves?limit=100");
    if (epoch !== state.epoch) { return; }
    const may = state.me && state.me.may.publish_curves;
    updateRows(document.getElementById("curves"), page.items, c => "curve-" + c.id,
      c => JSON.stringify([c.published, may]), c => {
        const tr = document.createElement("tr");
        tr.appendChild(text("td", String(c.id)));
        tr.appendChild(text("td", c.curve_key + ", version " + c.version));
        tr.appendChild(text("td", fidelityText(c.fidelity), "fidelity"));
        tr.appendChild(text("td", c.rattle_space_range ? c.rattle_space_range[0] + " to " + c.rattle_space_range[1] : "n/a"));
        const made = document.createElement("td");
        made.appendChild(document.createTextNode(when(c.created_at) + " by " + c.created_by + " (code " + c.code_version + ") from sweep "));
        made.appendChild(pageLink(c.job_id, "#/jobs/" + c.job_id, "id"));
        tr.appendChild(made);
        const published = document.createElement("td");
        if (c.published) { published.textContent = when(c.published_at) + " by " + c.published_by; }
        else if (may) {
          const button = text("button", "Publish", "publish");
          button.type = "button";
          button.addEventListener("click", () => { button.disabled = true; publishCurve(c, false); });
          published.appendChild(button);
        } else { published.textContent = "not published"; }
        tr.appendChild(published);
        return tr;
      });
  } catch (e) { if (!(e instanceof Refused)) { document.getElementById("curves-error").textContent = String(e); } }
}

// ---- A diagnosis' page ----

async function openDiagnosis(id, epoch) {
  try {
    const job = await api("/v1/jobs/" + encodeURIComponent(id));
    if (epoch !== state.epoch) { return; }
    if (job.status === "succeeded") { showDiagnosis(job); }
    else { diag.started = ACTIVE.has(job.status) ? job.id : null; diag.shown = null; showDiagnosisProgress(job); }
  } catch (e) {
    if (!(e instanceof Refused)) { document.getElementById("diagnosis").replaceChildren(text("div", String(e), "status-failed")); }
  }
}

// Every diagnosis, not only those among the latest jobs: the job list has no kind filter, so
// the page walks all submitted jobs (100 a page) on the first poll and every tenth after it,
// and the newest page on the others; diagnoses seen stay listed.
async function pollDiagnoses(epoch, walk) {
  try {
    const campaigns = await api("/v1/campaigns?limit=100");
    if (epoch !== state.epoch) { return; }
    renderCampaigns(campaigns.items);
    let cursor = null, pages = 0;
    do {
      const page = await api("/v1/jobs?limit=100&top_level=true" + (cursor ? "&cursor=" + encodeURIComponent(cursor) : ""));
      if (epoch !== state.epoch) { return; }
      for (const job of page.items) { if (job.kind === "diagnose") { diag.jobs.set(job.id, job); } }
      cursor = page.next_cursor;
      pages += 1;
    } while (walk && cursor && pages < 1000);
    const jobs = [...diag.jobs.values()].sort((x, y) => x.created_at < y.created_at ? 1 : x.created_at > y.created_at ? -1 : 0);
    renderDiagnoses(jobs);
    document.getElementById("diagnoses-error").textContent = "";
  } catch (e) { if (!(e instanceof Refused) && epoch === state.epoch) { document.getElementById("diagnoses-error").textContent = String(e); } }
}

// One poll at a time (a slow answer does not stack polls up).
async function poll() {
  if (state.polling || !state.token) { return; }
  state.polling = true;
  const epoch = state.epoch;
  const walk = state.ticks % 10 === 0;
  state.ticks += 1;
  const r = state.route;
  const jobs = r && r.page === "jobs" && !r.id ? pollJobs(epoch) : null;
  const page = r && r.page === "jobs" && r.id && (jobPage.id !== r.id || ACTIVE.has(jobPage.status)) ? loadJobPage(r.id, epoch) : null;
  try { await Promise.all([jobs, page, pollDiagnoses(epoch, walk)]); } finally { if (epoch === state.epoch) { state.polling = false; } }
}

document.getElementById("token-form").addEventListener("submit", event => {
  event.preventDefault();
  state.token = document.getElementById("token").value.trim();
  if (state.token) { sessionStorage.setItem("railwear-token", state.token); }
  signIn();
});
document.getElementById("sign-out").addEventListener("click", signOut);
document.getElementById("rail-search").addEventListener("submit", event => {
  event.preventDefault();
  const serial = document.getElementById("serial").value.trim();
  const compare = document.getElementById("compare").value.trim();
  if (serial) { go("#/rails/" + encodeURIComponent(serial) + (compare ? "?compare=" + encodeURIComponent(compare) : "")); }
});
document.getElementById("job-filters").addEventListener("submit", event => {
  event.preventDefault();
  const params = new URLSearchParams();
  for (const [key, id] of [["kind", "filter-kind"], ["status", "filter-status"], ["by", "filter-submitter"]]) {
    const v = document.getElementById(id).value.trim();
    if (v) { params.set(key, v); }
  }
  go("#/jobs" + (params.toString() ? "?" + params : ""));
});
document.getElementById("jobs-older").addEventListener("click", () => {
  if (!jobList.next) { return; }
  jobList.cursors = jobList.cursors.slice(0, jobList.index + 1).concat([jobList.next]);
  jobList.index += 1;
  pollJobs(state.epoch);
});
document.getElementById("jobs-newer").addEventListener("click", () => {
  if (jobList.index === 0) { return; }
  jobList.index -= 1;
  pollJobs(state.epoch);
});
window.addEventListener("hashchange", route);

// Submits a job; the button waits for the answer, then the page goes to the job's page.
document.getElementById("submit-job").addEventListener("submit", async event => {
  event.preventDefault();
  const button = document.getElementById("submit-button");
  const error = document.getElementById("submit-error");
  error.textContent = "";
  let params;
  try { params = JSON.parse(document.getElementById("submit-params").value); } catch (e) {
    error.textContent = "parameters: not JSON (" + e.message + ")"; return;
  }
  button.disabled = true;
  try {
    const job = await api("/v1/jobs", { method: "POST", headers: { "Content-Type": "application/json" },
      body: JSON.stringify({ kind: document.getElementById("submit-kind").value, params }) });
    go("#/jobs/" + job.id);
  } catch (e) { if (!(e instanceof Refused)) { error.textContent = String(e); } }
  finally { button.disabled = false; }
});

// Records a measurement of the rail shown; the button waits for the answer, then the report
// and history show it.
document.getElementById("record-measurement").addEventListener("submit", async event => {
  event.preventDefault();
  const button = document.getElementById("m-button");
  const error = document.getElementById("m-error");
  error.textContent = "";
  let dimensions;
  try { dimensions = JSON.parse(document.getElementById("m-dimensions").value); } catch (e) {
    error.textContent = "dimensions: not JSON (" + e.message + ")"; return;
  }
  const serial = state.route && state.route.page === "rails" ? state.route.id : null;
  if (!serial) { return; }
  button.disabled = true;
  try {
    await api("/v1/rails/" + encodeURIComponent(serial) + "/measurements", { method: "POST",
      headers: { "Content-Type": "application/json" }, body: JSON.stringify({
        dimensions_mm: dimensions, measured_by: document.getElementById("m-by").value.trim(),
        measured_at: document.getElementById("m-at").value.trim(), location: document.getElementById("m-location").value.trim() }) });
    route();
  } catch (e) { if (!(e instanceof Refused)) { error.textContent = String(e); } }
  finally { button.disabled = false; }
});

// Uploads a campaign document; the button waits for the answer.
document.getElementById("upload-campaign").addEventListener("submit", async event => {
  event.preventDefault();
  const button = document.getElementById("upload-button");
  const error = document.getElementById("upload-error");
  const file = document.getElementById("campaign-file").files[0];
  error.textContent = "";
  if (!file) { error.textContent = "choose a campaign file"; return; }
  button.disabled = true;
  const epoch = state.epoch;
  try {
    await api("/v1/campaigns", { method: "POST", headers: { "Content-Type": "application/json" }, body: await file.text() });
    if (epoch === state.epoch) { await pollDiagnoses(epoch, false); }
  } catch (e) { if (!(e instanceof Refused)) { error.textContent = String(e); } }
  finally { button.disabled = false; }
});
readToken();
if (state.token) { signIn(); } else { document.getElementById("error").textContent = "enter a token"; }
