"use strict";
const state = { token: "" };

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

function signOut() {
  sessionStorage.removeItem("railwear-token");
  state.token = "";
  document.getElementById("token").value = "";
  for (const id of ["jobs", "campaigns", "diagnoses"]) { document.getElementById(id).replaceChildren(); }
  for (const id of ["report", "curve", "diagnosis"]) { document.getElementById(id).replaceChildren(); }
  const result = document.getElementById("result");
  result.textContent = ""; result.hidden = true;
  document.getElementById("error").textContent = "signed out";
}

async function api(path, init) {
  const options = init || {};
  options.headers = Object.assign({ "Authorization": "Bearer " + state.token }, options.headers || {});
  const response = await fetch(path, options);
  const type = response.headers.get("content-type") || "";
  const body = type.includes("json") ? await response.json() : await response.text();
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
  a.addEventListener("click", action);
  return a;
}

async function showResult(path) {
  const pre = document.getElementById("result");
  pre.hidden = false;
  try {
    const body = await api(path);
    pre.textContent = typeof body === "string" ? body.slice(0, 20000) : JSON.stringify(body, null, 2);
  } catch (e) { pre.textContent = String(e); }
}

function renderJobs(page) {
  const tbody = document.getElementById("jobs");
  tbody.replaceChildren();
  for (const job of page.items) {
    const row = document.createElement("tr");
    row.id = "job-" + job.id;
    row.dataset.status = job.status;
    row.appendChild(text("td", job.id.slice(0, 8)));
    row.appendChild(text("td", job.kind));
    row.appendChild(text("td", job.status, "status status-" + job.status));
    const progress = document.createElement("td");
    if (job.progress) {
      const bar = document.createElement("span"); bar.className = "bar";
      const fill = document.createElement("span");
      fill.style.width = Math.round(100 * job.progress.fraction) + "%";
      bar.appendChild(fill); progress.appendChild(bar);
      // A diagnosis counts simulations done, the others simulated time.
      let label = " " + Math.round(100 * job.progress.fraction) + "% (" + (job.kind === "diagnose"
        ? Math.round(job.progress.simulated_time_s) + " / " + Math.round(job.progress.end_time_s) + " simulations"
        : "t = " + job.progress.simulated_time_s.toFixed(2) + " / " + job.progress.end_time_s.toFixed(2) + " s");
      if (job.status === "running" && job.progress.eta_s != null) { label += ", ETA " + Math.round(job.progress.eta_s) + " s"; }
      progress.appendChild(document.createTextNode(label + ")"));
    }
    if (job.children) {
      // A sweep fanned out into one child job per point, run by any worker.
      const c = job.children;
      let label = " " + c.succeeded + "/" + c.total + " points done";
      if (c.failed > 0) { label += ", " + c.failed + " failed"; }
      if (c.cancelled > 0) { label += ", " + c.cancelled + " cancelled"; }
      progress.appendChild(text("span", label, "children"));
    }
    row.appendChild(progress);
    row.appendChild(text("td", job.created_at.replace("T", " ").slice(0, 19)));
    const links = document.createElement("td");
    if (job.status === "succeeded") {
      links.appendChild(link("result", () => showResult(job.links.result)));
      links.appendChild(link("tracks (CSV, every 100th)", () => showResult(job.links.self + "/tracks?format=csv&every=100")));
    } else if (job.error) {
      links.appendChild(text("span", job.error));
    }
    row.appendChild(links);
    tbody.appendChild(row);
  }
}

async function pollJobs() {
  if (!state.token) { document.getElementById("error").textContent = "enter a token"; return; }
  try {
    // Submitted jobs only: a sweep's per-point child jobs show as its progress.
    renderJobs(await api("/v1/jobs?limit=50&top_level=true"));
    document.getElementById("error").textContent = "";
  } catch (e) { document.getElementById("error").textContent = String(e); }
}

function curveSvg(report) {
  const pts = report.k_sl_curve;
  if (!pts || pts.length === 0) { return null; }
  const W = 480, H = 280, m = 40;
  const xs = pts.map(p => p[0]).concat([report.rattle_space]);
  const x0 = Math.min(...xs), x1 = Math.max(...xs);
  const y0 = 0.0, y1 = 1.05;
  const sx = x => m + (W - 2 * m) * (x - x0) / ((x1 - x0) || 1);
  const sy = y => H - m - (H - 2 * m) * (y - y0) / (y1 - y0);
  const ns = "http://www.w3.org/2000/svg";
  const svg = document.createElementNS(ns, "svg");
  svg.setAttribute("width", W); svg.setAttribute("height", H); svg.setAttribute("id", "curve-plot");
  const line = (factor, color, dash) => {
    const pl = document.createElementNS(ns, "polyline");
    pl.setAttribute("points", pts.map(p => sx(p[0]) + "," + sy(factor * p[1])).join(" "));
    pl.setAttribute("fill", "none"); pl.setAttribute("stroke", color);
    if (dash) { pl.setAttribute("stroke-dasharray", "5,4"); }
    svg.appendChild(pl);
  };
  const axis = (xa, ya, xb, yb) => {
    const l = document.createElementNS(ns, "line");
    l.setAttribute("x1", xa); l.setAttribute("y1", ya); l.setAttribute("x2", xb); l.setAttribute("y2", yb);
    l.setAttribute("stroke", "#444"); svg.appendChild(l);
  };
  const label = (x, y, s) => {
    const t = document.createElementNS(ns, "text");
    t.setAttribute("x", x); t.setAttribute("y", y); t.setAttribute("font-size", "11"); t.textContent = s;
    svg.appendChild(t);
  };
  axis(m, H - m, W - m, H - m); axis(m, m, m, H - m);
  label(W / 2 - 40, H - 8, "rattle space k_rs"); label(4, m - 8, "K_SL");
  label(m - 4, H - m + 14, x0.toFixed(3)); label(W - m - 20, H - m + 14, x1.toFixed(3));
  label(4, sy(1) + 4, "1.0"); label(4, sy(0.5) + 4, "0.5");
  line(1.0, "#0a58ca", false); line(0.9, "#6c757d", true); line(0.8, "#adb5bd", true);
  if (report.service_life) {
    const c = document.createElementNS(ns, "circle");
    c.setAttribute("cx", sx(report.rattle_space)); c.setAttribute("cy", sy(report.service_life.k_sl));
    c.setAttribute("r", 5); c.setAttribute("fill", "#b02a37"); svg.appendChild(c);
  }
  return svg;
}

async function loadReport() {
  const serial = document.getElementById("serial").value.trim();
  const out = document.getElementById("report");
  const plot = document.getElementById("curve");
  out.replaceChildren(); plot.replaceChildren();
  if (!serial) { return; }
  try {
    const compare = document.getElementById("compare").value.trim();
    const r = await api("/v1/rails/" + encodeURIComponent(serial) + "/report" +
      (compare ? "?compare=" + encodeURIComponent(compare) : ""));
    out.appendChild(text("div", "Rail " + r.serial + ": rattle space k_rs = " + r.rattle_space.toFixed(4) +
      " (measured " + r.measurement.measured_at + " by " + r.measurement.measured_by + " at " + r.measurement.location + ")"));
    if (r.service_life) {
      const s = r.service_life;
      out.appendChild(text("div", "K_SL = " + s.k_sl.toFixed(3) + " (bands 0.9: " + s.k_sl_band_90.toFixed(3) +
        ", 0.8: " + s.k_sl_band_80.toFixed(3) + "); service life " + s.penalized_life_h.toFixed(0) + " h of " +
        s.design_life_h.toFixed(0) + " h design (" + s.penalized_life_band_90_h.toFixed(0) + " / " +
        s.penalized_life_band_80_h.toFixed(0) + " h conservative)", "status-succeeded"));
    }
    if (r.missing_curve) { out.appendChild(text("div", r.missing_curve.detail, "status-cancelled")); }
    if (r.comparison) { out.appendChild(comparisonLine(r.comparison)); }
    const svg = curveSvg(r);
    if (svg) { plot.appendChild(svg); }
  } catch (e) { out.appendChild(text("div", String(e), "status-failed")); }
}

// K_SL and the penalized life under another stored curve (`?compare=<curve id>`, issue 26).
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

const diag = { may: false, campaigns: new Map(), shown: null, started: null };

// Numbers with their units. Held-out errors are RMS standardized errors: multiples of each
// observation's standard uncertainty (sigma).
const fmt = {
  num: (x, digits) => (x == null || !isFinite(x)) ? "n/a" :
    (Math.abs(x) !== 0 && (Math.abs(x) >= 1e4 || Math.abs(x) < 1e-3)) ? x.toExponential(digits - 1) : x.toPrecision(digits),
  sigma: x => fmt.num(x, 3) + " \u03c3",
  percent: x => (x == null || !isFinite(x)) ? "n/a" : (100 * x).toFixed(1) + " %",
  bytes: n => n >= 1048576 ? (n / 1048576).toFixed(1) + " MiB" : n >= 1024 ? (n / 1024).toFixed(1) + " KiB" : n + " B",
  withUnit: (x, unit) => fmt.num(x, 3) + (unit ? " " + unit : ""),
};

async function loadWhoAmI() {
  try {
    const me = await api("/v1/whoami");
    diag.may = me.may.diagnose;
  } catch (e) { diag.may = false; }
  document.getElementById("diagnose-options").hidden = !diag.may;
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

async function startDiagnosis(campaign) {
  const error = document.getElementById("diagnose-error");
  error.textContent = "";
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
    pollDiagnoses();
  } catch (e) { error.textContent = String(e); }
}

function renderCampaigns(page) {
  const tbody = document.getElementById("campaigns");
  tbody.replaceChildren();
  diag.campaigns.clear();
  for (const c of page.items) {
    diag.campaigns.set(c.id, c);
    const row = document.createElement("tr");
    row.id = "campaign-" + c.id;
    row.appendChild(text("td", c.name));
    row.appendChild(text("td", c.created_at.replace("T", " ").slice(0, 19) + " by " + c.created_by));
    const n = c.counts;
    row.appendChild(text("td", n.tests + " / " + n.specimens + " / " + n.increments + " / " + n.accelerometer_records));
    row.appendChild(text("td", fmt.bytes(c.content_bytes)));
    const action = document.createElement("td");
    if (diag.may) {
      const button = text("button", "Start diagnosis", "start-diagnosis");
      button.addEventListener("click", () => startDiagnosis(c));
      action.appendChild(button);
    }
    row.appendChild(action);
    tbody.appendChild(row);
  }
}

function progressCell(job) {
  const cell = document.createElement("td");
  if (job.progress) {
    const bar = document.createElement("span"); bar.className = "bar";
    const fill = document.createElement("span");
    fill.style.width = Math.round(100 * job.progress.fraction) + "%";
    bar.appendChild(fill); cell.appendChild(bar);
    // A diagnosis reports simulations done of simulations planned.
    let label = " " + Math.round(100 * job.progress.fraction) + "% (" + Math.round(job.progress.simulated_time_s) +
      " / " + Math.round(job.progress.end_time_s) + " simulations";
    if (job.status === "running" && job.progress.eta_s != null) { label += ", ETA " + Math.round(job.progress.eta_s) + " s"; }
    cell.appendChild(document.createTextNode(label + ")"));
  }
  return cell;
}

function renderDiagnoses(jobs) {
  const tbody = document.getElementById("diagnoses");
  tbody.replaceChildren();
  for (const job of jobs) {
    const row = document.createElement("tr");
    row.id = "diagnosis-" + job.id;
    row.dataset.status = job.status;
    row.appendChild(text("td", job.id.slice(0, 8)));
    const campaign = diag.campaigns.get(job.params.campaign_id);
    row.appendChild(text("td", campaign ? campaign.name : job.params.campaign_id.slice(0, 8)));
    row.appendChild(text("td", job.status, "status status-" + job.status));
    row.appendChild(progressCell(job));
    row.appendChild(text("td", job.created_at.replace("T", " ").slice(0, 19)));
    const links = document.createElement("td");
    if (job.status === "succeeded") {
      links.appendChild(link("report", () => showDiagnosis(job)));
    } else if (job.error) {
      links.appendChild(text("span", job.error));
    }
    row.appendChild(links);
    tbody.appendChild(row);
    if (job.id === diag.started) {
      if (job.status === "succeeded") { diag.started = null; showDiagnosis(job); }
      else if (job.status === "failed" || job.status === "cancelled") { diag.started = null; showDiagnosisProgress(job); }
    }
  }
}

function showDiagnosisProgress(job) {
  const out = document.getElementById("diagnosis");
  out.replaceChildren();
  out.dataset.job = job.id;
  delete out.dataset.verdict;
  const line = job.error ? "Diagnosis " + job.id.slice(0, 8) + " " + job.status + ": " + job.error
    : "Diagnosis " + job.id.slice(0, 8) + " " + job.status + "; its report shows here when it succeeds.";
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
  const out = document.getElementById("diagnosis");
  out.replaceChildren();
  out.dataset.job = job.id;
  delete out.dataset.verdict;
  try {
    const result = await api(job.links.result);
    const r = result.summary;
    out.appendChild(text("h3", "Diagnosis of " + r.campaign + " (job " + job.id.slice(0, 8) + ")"));
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
      }
      out.appendChild(text("div", "Held-out RMS standardized error: " + fmt.sigma(b.held_out_error_before) +
        " before, " + fmt.sigma(b.held_out_error_after) + " after; the gap shrinks by " + fmt.percent(b.shrink) +
        " (90 % interval " + fmt.percent(b.shrink_interval[0]) + " to " + fmt.percent(b.shrink_interval[1]) +
        "); lack-of-fit p-value of what is left " + fmt.num(b.residual_p_value, 3) + ".", "best-effect"));
      const params = b.parameters.map(p => row([
        p.effect, p.name, fmt.withUnit(p.value, p.unit),
        p.fitted ? interval(p.interval, p.unit) : "held at default",
        interval(p.bounds, p.unit),
      ]));
      out.appendChild(table(["Effect", "Parameter", "Value", "95 % interval", "Physical bounds"], params));
    } else {
      out.appendChild(text("div", "No effect named. Nominal model: held-out RMS standardized error " +
        fmt.sigma(r.nominal.held_out_error) + ", chi-square " + fmt.num(r.nominal.chi2, 3) + " on " +
        fmt.num(r.nominal.dof, 3) + " degrees of freedom (p = " + fmt.num(r.nominal.p_value, 3) + ").", "best-effect"));
    }

    out.appendChild(text("h4", "Ranking (held out: " + r.held_out + ")"));
    const runnersUp = new Set(r.indistinguishable);
    const ranking = r.ranking.concat(r.pairs).map((e, i) => {
      const mark = e.name === (r.best_effect && r.best_effect.name) ? "best"
        : runnersUp.has(e.name) ? "indistinguishable from the best" : "";
      const tr = row([String(i + 1), e.name, fmt.num(e.held_out_gain, 3) + " nats" + (e.held_out_gain_interval
        ? " (90 %: " + fmt.num(e.held_out_gain_interval[0], 3) + " to " + fmt.num(e.held_out_gain_interval[1], 3) + ")" : ""), fmt.sigma(e.held_out_error),
        fmt.percent(e.explained_share), fmt.num(e.residual_p_value, 3), fmt.percent(e.p_first),
        e.explains ? "yes" : "no", mark], runnersUp.has(e.name) ? "indistinguishable" : "");
      tr.dataset.effect = e.name;
      return tr;
    });
    const rankTable = table(["#", "Effect", "Held-out log-likelihood gain", "Held-out RMS error",
      "Excess chi-square removed", "Lack-of-fit p", "P(first), bootstrap", "Explains", ""], ranking);
    rankTable.id = "diagnosis-ranking";
    out.appendChild(rankTable);

    out.appendChild(text("h4", "Where the nominal model misses (Holm-adjusted p < 0.05)"));
    const flagged = r.where.groups.filter(g => g.flagged);
    if (flagged.length === 0) {
      out.appendChild(text("div", "No group flagged.", "where-none"));
    } else {
      const groups = flagged.map(g => {
        const unit = g.by === "frequency_band" ? "dB (measured / model)" : "\u03c3";
        const tr = row([g.by, g.label, fmt.num(g.mean_residual, 3) + " " + unit, fmt.num(g.z, 3),
          fmt.num(g.p_adjusted, 3), fmt.num(g.observations, 3)]);
        tr.className = "flagged";
        return tr;
      });
      const whereTable = table(["By", "Group", "Mean residual", "Bias score z", "Adjusted p", "Observations (weighted)"], groups);
      whereTable.id = "diagnosis-where";
      out.appendChild(whereTable);
    }

    const budget = r.where.energy_budget;
    if (budget && budget.tests.length > 0) {
      out.appendChild(text("h4", "Energy budget of the nominal model (work by kind, J) and the coefficient each wear mechanism needs"));
      const work = [];
      for (const t of budget.tests) {
        for (const c of t.contacts) {
          work.push(row([t.test, c.contact, fmt.num(t.drive_j, 3), fmt.num(c.friction_j, 3), fmt.num(c.damping_j, 3),
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

    // The figures, fetched with the token and shown as images (an <img> runs no script).
    const plots = document.createElement("div");
    plots.className = "plots";
    out.appendChild(plots);
    // In the report's order: where (residuals, energy budget), which, how far.
    const order = ["residuals.svg", "energy_budget.svg", "ranking.svg", "before_after.svg"];
    const rank = name => order.indexOf(name) < 0 ? order.length : order.indexOf(name);
    for (const plot of result.plots.slice().sort((a, b) => rank(a.name) - rank(b.name))) {
      const response = await fetch(plot.url, { headers: { "Authorization": "Bearer " + state.token } });
      if (!response.ok) { plots.appendChild(text("div", plot.name + ": " + response.status, "status-failed")); continue; }
      const img = document.createElement("img");
      img.alt = plot.name;
      img.dataset.plot = plot.name;
      img.src = URL.createObjectURL(await response.blob());
      plots.appendChild(img);
    }
    out.dataset.verdict = r.verdict;
  } catch (e) {
    diag.shown = null;
    out.appendChild(text("div", String(e), "status-failed"));
  }
}

async function pollDiagnoses() {
  if (!state.token) { return; }
  try {
    renderCampaigns(await api("/v1/campaigns?limit=100"));
    // Diagnoses among the latest 100 submitted jobs (the job list has no kind filter).
    const page = await api("/v1/jobs?limit=100&top_level=true");
    renderDiagnoses(page.items.filter(j => j.kind === "diagnose"));
    document.getElementById("diagnoses-error").textContent = "";
  } catch (e) { document.getElementById("diagnoses-error").textContent = String(e); }
}

function poll() { pollJobs(); pollDiagnoses(); }

document.getElementById("save-token").addEventListener("click", () => {
  state.token = document.getElementById("token").value.trim();
  sessionStorage.setItem("railwear-token", state.token);
  loadWhoAmI().then(poll);
});
document.getElementById("sign-out").addEventListener("click", signOut);
document.getElementById("load-report").addEventListener("click", loadReport);
readToken();
loadWhoAmI().then(poll);
setInterval(poll, 1000);
