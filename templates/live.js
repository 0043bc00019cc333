// drillfric live page (drillfric/livepage.py): polls the live process and redraws.
// Every text goes in with textContent; a missing number is NaN in a figure (not drawn),
// never 0, and "withheld" with the reason in the text.
(function () {
  "use strict";
  const byId = (id) => document.getElementById(id);
  const put = (id, text) => { byId(id).textContent = text; };
  const num = (a) => Float64Array.from(a || [], (v) => (v === null ? NaN : v));
  const scaled = (a, k) => num(a).map((v) => v * k);
  const known = (v) => v !== null && v !== undefined;
  // no "-0.0": a value that rounds to zero is 0 (a fifth newcomer read "bit speed -0.0 rpm")
  const fixed = (v, digits) => (known(v) ? (Number(Number(v).toFixed(digits)) || 0).toFixed(digits)
    : "—");
  let doc = null;
  let polls = 0;

  async function get(path) {
    const reply = await fetch(path, { cache: "no-store" });
    if (!reply.ok) throw new Error(path + " answered " + reply.status);
    return reply.json();
  }

  function withheld(why) {
    return "withheld: " + (why || "no estimate yet");
  }

  // A value older than this behind the newest sample [s] shows its age, greyed: it is not
  // current (issue 35: a segment that had ended 150 s before read as the open one).
  const OLD_S = 5;
  const OPEN_IDS = ["open-mu-k", "open-mu-s", "open-bit-rpm", "open-severity"];

  function showOpen(open, row, last, behindS) {
    if (!open) {
      OPEN_IDS.forEach((id) => { put(id, "—"); byId(id).classList.remove("old"); });
      // the estimates lagging the data: an open segment may not be published yet, so
      // "none" would read as current (issue 35)
      const late = known(behindS) && behindS > OLD_S;
      put("open-segment", late ? "not known yet: the estimates are " + fixed(behindS, 0)
        + " s behind the newest sample" : "none");
      byId("open-segment").classList.toggle("old", late);
      return;
    }
    const age = known(last) && known(open.t_end_s) ? last - open.t_end_s : 0;
    const old = age > OLD_S;
    OPEN_IDS.concat(["open-segment"]).forEach((id) => byId(id).classList.toggle("old", old));
    const why = row ? row.message : "";
    const ok = open.status === "ok";  // a skipped or failed segment's numbers are withheld
    put("open-segment", "segment " + open.segment + " (" + open.kind.replace(/_/g, " ") + ", "
        + fixed(open.t_start_s, 0) + "–" + fixed(open.t_end_s, 0) + " s, " + open.status + ")"
        + (old ? " — as of " + age.toFixed(0) + " s before the newest sample, not current" : ""));
    // friction that moves within the segment (flag mu_k_drift): μ_k(t) of its last window
    const moving = ok && open.mu_k_drift && known(open.mu_k_last) && known(open.mu_k_drift_per_h)
      ? " — friction moving: μ_k(t) " + fixed(open.mu_k_last, 3) + " at the last window, "
        + (open.mu_k_drift_per_h > 0 ? "+" : "") + fixed(open.mu_k_drift_per_h, 3) + "/h"
      : "";
    put("open-mu-k", (ok && known(open.mu_k)
      ? fixed(open.mu_k, 3) + (open.kind === "on_bottom_rotating" ? " apparent" : "")
      : withheld(why)) + moving);
    put("open-mu-s", ok && known(open.mu_s) ? fixed(open.mu_s, 3)
      : ok && known(open.mu_s_lower_bound) ? "≥ " + fixed(open.mu_s_lower_bound, 3) + " (not identifiable)"
        : withheld(ok ? "not identifiable from these data" : why));
    put("open-bit-rpm", row && row.bit_speed_resolved === false
      ? withheld(row.bit_speed_reason || "bit speed not resolved")
      : ok && known(open.bit_rpm) ? fixed(open.bit_rpm, 1) + " rpm"
        + (known(open.bha_rpm) && open.bha_rpm !== open.bit_rpm
          ? " (BHA " + fixed(open.bha_rpm, 1) + " rpm + mud motor)" : "")
        : withheld(open.bit_rpm_reason || why));
    put("open-severity", ok && known(open.stick_slip_severity)
      ? fixed(open.stick_slip_severity, 2)
      : ok && open.stick_slip_beyond_validated
        ? withheld("severe, beyond the validated range (estimated ≥ 2.1)") : withheld(why));
  }

  function showStatus(s, segs) {
    put("well-name", s.well || "waiting for data");
    put("last-sample", known(s.last_sample_time_s)
      ? fixed(s.last_sample_time_s, 2) + " s" + (s.last_sample_utc ? " (" + s.last_sample_utc + ")" : "")
      : "no data yet");
    put("rows", String(s.rows));
    put("rig-state", s.rig_state ? s.rig_state.replace(/_/g, " ") : "—");
    const open = s.open_segment;
    showOpen(open, open ? segs.segments.find((r) => r.id === open.segment) : null,
      s.last_sample_time_s, s.behind_s);
    const latest = s.latest;
    const latestOld = !!(latest && latest.old);
    put("latest", latest ? "segment " + latest.segment + ": μ_k " + fixed(latest.mu_k, 3) + ", μ_s "
      + (known(latest.mu_s) ? fixed(latest.mu_s, 3) : "not identified")
      + (latestOld ? " — as of " + fixed(latest.age_s, 0) + " s before the newest sample" : "")
      : "none yet");
    byId("latest").classList.toggle("old", latestOld);
    put("updated", s.updated_utc);
    const list = byId("alerts");
    list.replaceChildren();
    for (const alert of s.alerts) {
      const item = document.createElement("li");
      // an alert resting on rows older than OLD_S behind the newest sample says how old
      // and is greyed: it is not about now (issue 35)
      const old = alert.old || (known(alert.time_s) && known(s.last_sample_time_s)
        && s.last_sample_time_s - alert.time_s > OLD_S);
      item.className = alert.kind + (old ? " old" : "");
      item.textContent = alert.kind.replace(/_/g, " ") + ": " + alert.message
        + (known(alert.time_s) ? " (log time " + fixed(alert.time_s, 1) + " s"
          + (old ? ", " + fixed(s.last_sample_time_s - alert.time_s, 0)
            + " s before the newest sample, not current" : "") + ")" : "");
      list.appendChild(item);
    }
    if (!s.alerts.length) list.appendChild(Object.assign(document.createElement("li"), { textContent: "none" }));
    put("behind", known(s.behind_s) ? fixed(s.behind_s, 0) + " s" : "—");
    byId("behind").classList.toggle("old", known(s.behind_s) && s.behind_s > OLD_S);
  }

  function showTracks(t) {
    doc.get_model_by_name("surface").data = {
      x: num(t.time_s), rpm: num(t.surface_rpm),
      torque_kNm: scaled(t.surface_torque_Nm, 1e-3), hookload_kN: scaled(t.hookload_N, 1e-3),
    };
    doc.get_model_by_name("bit").data = {
      x: num(t.bit.time_s), rpm: num(t.bit.bit_rpm_est),
      low: num(t.bit.bit_rpm_est_min), high: num(t.bit.bit_rpm_est_max),
      bha: num(t.bit.bha_rpm_est),
    };
    put("bit-withheld", t.bit.withheld.length ? "Bit speed withheld: " + t.bit.withheld
      .map((w) => "segment " + w.segment + " — " + w.reason).join("; ") : "");
  }

  function cell(row, text, cls) {
    const td = document.createElement("td");
    td.textContent = text;
    if (cls) td.className = cls;
    row.appendChild(td);
  }

  function showSegments(g) {
    const rows = g.segments;
    const column = (key) => num(rows.map((r) => r[key]));
    doc.get_model_by_name("segments").data = {
      id: rows.map((r) => r.id), depth: column("bit_depth_m"), mu_k: column("plot_mu_k"),
      mu_app: column("plot_mu_app"), mu_s: column("plot_mu_s"), mu_s_lb: column("plot_mu_s_lb"),
      severity: column("plot_severity"), fill: column("plot_fill"),
    };
    const body = byId("segments-table").tBodies[0];
    body.replaceChildren();
    for (const r of rows.slice().reverse()) {
      const tr = document.createElement("tr");
      tr.className = r.status !== "ok" ? r.status : r.converged ? "" : "unconverged";
      cell(tr, String(r.id) + (r.open ? " (open)" : ""));
      cell(tr, String(r.kind).replace(/_/g, " "));
      cell(tr, known(r.bit_depth_m) ? fixed(r.bit_depth_m, 1) : "—", "num");
      cell(tr, fixed(r.t_start_s, 0) + "–" + fixed(r.t_end_s, 0));
      cell(tr, r.mu_k_text, "num");
      cell(tr, r.mu_s_text, "num");
      cell(tr, r.severity_text || "—", "num");
      cell(tr, r.status_text);
      cell(tr, r.message || "");
      body.appendChild(tr);
    }
  }

  async function poll() {
    try {
      const [status, tracks, segs] = await Promise.all(
        [get("/live.json"), get("/tracks.json"), get("/segments.json")]);
      showStatus(status, segs);
      showTracks(tracks);
      showSegments(segs);
      polls += 1;
      document.body.dataset.polls = String(polls);
      document.body.classList.remove("stale");
      put("connection", "live: updated every POLL_MS ms");
    } catch (error) {
      document.body.classList.add("stale");
      put("connection", "the live process does not answer (" + error.message
        + "): the numbers below are the last it sent");
    }
    setTimeout(poll, POLL_MS);
  }

  const items = JSON.parse(byId("bokeh-items").textContent);
  Bokeh.embed.embed_item(items[0]).then(() => {
    doc = Bokeh.documents[Bokeh.documents.length - 1];
    poll();
  });
})();
