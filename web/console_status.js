// Every outcome shown: banners for the server's warnings and errors, for a refused action
// (status.last_error) and for the demo's result; the platform's status (with what an overrun
// is), the scene's limits on the gauges, the forces, the recordings. Connects last.
"use strict";

// ---------------------------------------------------------------------------------------------
// Banners: one per distinct message, repeated ones counted, each stays until dismissed.
// kind: "error", "warning" or "ok".
function banner(kind, text) {
  for (const b of $("banners").children) {
    if (b.dataset.text === text) {
      b.dataset.count = String(Number(b.dataset.count) + 1);
      b.querySelector(".count").textContent = "×" + b.dataset.count;
      b.className = "banner " + kind;
      return;
    }
  }
  const b = document.createElement("div");
  b.className = "banner " + kind;
  b.setAttribute("role", kind === "ok" ? "status" : "alert");
  b.dataset.text = text;
  b.dataset.count = "1";
  const span = document.createElement("span"), count = document.createElement("span"), close = document.createElement("button");
  span.className = "text";
  span.textContent = text;
  count.className = "count";
  close.textContent = "✕";
  close.title = "Dismiss";
  close.addEventListener("click", () => b.remove());
  b.append(span, count, close);
  $("banners").append(b);
  while ($("banners").childElementCount > 4) $("banners").firstChild.remove();  // the newest four
}
mc.banners = () => Array.from($("banners").children, (b) => b.dataset.text);

// Foxglove status messages: level 1 is a warning, 2 an error; info (0) goes to the log only.
function onServerStatus(m) {
  if (m.level === 2) banner("error", m.message);
  else if (m.level === 1) banner("warning", m.message);
}

// last_error: the control thread's (or the request's) refusal of demo, restart, reset or next_part. Shown
// when it changes to a new text, and again when an action was just pressed and it is still set
// (the same refusal twice is still an answer). Statuses sampled before the action reached the
// server (5 Hz, under 300 ms after the press) do not count.
let lastError = "";
function watchLastError(s) {
  const error = typeof s.last_error === "string" ? s.last_error : "";
  const a = mc.lastAction, since = a ? performance.now() - a.at : Infinity;
  const answered = a && ["demo", "restart", "reset", "next_part"].includes(a.name) && since > 300 && since < 3000;
  if (error && (error !== lastError || answered)) {
    banner("error", error);
    mc.lastAction = null;  // answered
  } else if (answered) {
    mc.lastAction = null;  // accepted: last_error is empty
  }
  lastError = error;
}

// The demo's result (status.demo_result: null or {outcome (running, placed, inserted, missed,
// gave_up), phase, placement_error_m, reason, duration_s}; absent from older servers). A banner
// when the demo ends while the page watches.
function demoText(r) {
  const dur = isNum(r.duration_s) ? `${r.duration_s.toFixed(0)} s` : "";
  if (r.outcome === "running") return `Demo: running${r.phase ? " (" + r.phase + ")" : ""}${dur ? ", " + dur : ""}`;
  if (r.outcome === "gave_up") return `Demo gave up${r.phase ? " in " + r.phase : ""}: ${r.reason || "no reason given"}${dur ? " (" + dur + ")" : ""}`;
  const err = isNum(r.placement_error_m) ? `, error ${(r.placement_error_m * um).toFixed(1)} µm` : "";
  return `Demo: ${r.outcome}${err}${dur ? ", " + dur : ""}`;
}
let lastDemoKey;  // undefined until the first status: a result older than the page is no news
function watchDemo(s) {
  const r = s.demo_result && typeof s.demo_result === "object" ? s.demo_result : null;
  const key = r ? r.outcome + "/" + r.duration_s : "";
  if (lastDemoKey !== undefined && key !== lastDemoKey && r && r.outcome !== "running")
    banner(r.outcome === "gave_up" || r.outcome === "missed" ? "warning" : "ok", demoText(r));
  lastDemoKey = key;
  return r;
}

// ---------------------------------------------------------------------------------------------
// Status. Overruns are shown against the ticks run, their recent rate colouring them: a few are
// the price of a shared machine; a sustained rate means late control.
const kOverrunHelp =
  "An overrun is a loop tick that finished after its deadline: its work took longer than the " +
  "period (100 µs at the 10 kHz base rate), or it started a full period late (the loop thread " +
  "was preempted). The loop catches up at the next ticks (far behind, it skips them), so the " +
  "control acts late by that much. Not a fault unless sustained.";
const overrunHistory = [];  // [ticks, overruns] of the last ~5 s of statuses
function overrunRow(s) {
  if (!isNum(s.ticks) || s.ticks <= 0) return [String(s.overruns), undefined];
  overrunHistory.push([s.ticks, s.overruns]);
  while (overrunHistory.length > 25) overrunHistory.shift();
  const [t0, o0] = overrunHistory[0];
  const recent = s.ticks > t0 ? (s.overruns - o0) / (s.ticks - t0) : 0;
  const pct = (x) => (100 * x < 0.1 && x > 0 ? "< 0.1" : (100 * x).toFixed(1)) + " %";
  return [`${s.overruns} (${pct(s.overruns / s.ticks)} of ${s.ticks} ticks; last 5 s ${pct(recent)})`, recent < 0.01];
}
// The grip force seen by the camera (/platform/status "grip_vision"), beside the sensor's.
function showGripVision(g) {
  $("grip-vision-row").hidden = !g;
  if (!g) return;
  const f = g.grip_force_N;
  $("grip-vision-gauge").value = isNum(f) ? Math.max(0, f * um) : 0;
  $("grip-vision-out").textContent = isNum(f) ? (f * um).toFixed(1) + " µN" : g.state === "untared" ? "press Tare" : g.state;
  $("grip-vision-out").title = g.error || `gap ${(g.gap_m * um).toFixed(1)} µm, drive ${(g.free_opening_m * um).toFixed(1)} µm, correlation ${g.confidence.toFixed(2)}`;
  $("grip-vision-out").className = g.state === "measuring" ? "" : "bad";
  // The contact force along the closing axis (signed: + along the fingers' x); null without the
  // stage's sensors (the tips are then the only tool point there is).
  const c = g.contact_force_N;
  $("contact-vision-row").hidden = false;
  const unit = forceUnit();
  $("contact-vision-gauge").max = $("contact-gauge").max;
  $("contact-vision-gauge").high = $("contact-gauge").high;
  $("contact-vision-gauge").value = isNum(c) ? Math.abs(c) * unit.scale : 0;
  $("contact-vision-out").textContent = isNum(c) ? (c < 0 ? "−" : "") + fmtForce(unit, Math.abs(c)) : g.state === "measuring" ? "no stage sensor" : "—";
  $("contact-vision-out").title = isNum(g.bend_m) ? `tips bent ${(g.bend_m * um).toFixed(2)} µm` : "";
}
// The fingertips' levelling (/platform/status "levelling"): its state, why it failed, the tips'
// misalignment (null: the gripper does not know it).
function showLevelling(l) {
  $("levelling-row").hidden = !l;
  if (!l) return;
  const dz = (m) => (isNum(m) ? (m * um).toFixed(2) + " µm" : "—");
  const text = {
    idle: "tips " + dz(l.misalignment_m) + " apart",
    running: `${l.phase} (pass ${l.passes}): tips ${dz(l.misalignment_m)} apart; hold the deadman`,
    done: `done in ${l.passes} passes: tips ${dz(l.misalignment_before_m)} → ${dz(l.misalignment_m)} apart`,
    failed: `failed: ${l.failure}; tips ${dz(l.misalignment_m)} apart`,
  }[l.state];
  $("levelling-out").textContent = text || l.state;
  $("levelling-out").className = l.state === "failed" ? "bad" : "";
  $("levelling-out").title = `peak tip contact ${(l.peak_contact_N * um).toFixed(1)} µN`;
  $("level-tips").disabled = l.state === "running";
}
listen("/platform/status", (s) => {
  mc.status = s;
  showGripVision(s.grip_vision);
  showLevelling(s.levelling);
  const demo = watchDemo(s);
  watchLastError(s);
  const rows = [
    ["time", s.t_s.toFixed(1) + " s"],
    ["e-stop", s.estopped ? "LATCHED" : "clear", !s.estopped],
    ["control", s.controlled ? "a client" : "nobody", true],
    ["watchdog", s.console_fresh ? "fresh" : "holding", s.console_fresh],
    ["mode", s.demo ? "demo: " + s.demo_phase : "console", true],
  ];
  if (demo) rows.push(["demo", demoText(demo), demo.outcome !== "gave_up" && demo.outcome !== "missed"]);
  for (const [name, state] of Object.entries(s.lifecycle)) rows.push([name, state, state === "active"]);
  const [overruns, ok] = overrunRow(s);
  rows.push(["loop overruns", overruns, ok, kOverrunHelp]);
  rows.push(["tick p99", s.tick_p99_us.toFixed(1) + " µs (CPU " + s.tick_cpu_p99_us.toFixed(1) + " µs)", true]);
  rows.push(["clients", String(s.clients), true]);
  rows.push(["recording", s.recording || "off", true]);
  const lat = s.command_latency_ms;
  if (lat && lat.count > 0) rows.push(["command latency", "p50 " + lat.p50.toFixed(2) + " ms, p99 " + lat.p99.toFixed(2) + " ms", lat.p99 < 5]);
  if (s.last_error) rows.push(["last error", s.last_error, false]);
  const table = $("status");
  table.innerHTML = "";
  for (const [name, value, good, help] of rows) {
    const tr = document.createElement("tr");
    const a = document.createElement("td"), b = document.createElement("td");
    a.textContent = name;
    b.textContent = value;
    if (good !== undefined) b.className = good ? "ok" : "bad";
    if (help) tr.title = help;
    tr.append(a, b);
    table.append(tr);
  }
  $("estop").classList.toggle("latched", s.estopped);
  $("record").textContent = s.recording ? "Stop recording" : "Record";
  $("record").classList.toggle("on", !!s.recording);
  $("record-video").disabled = !!s.recording;  // chosen per recording, before it starts
  if ((s.recording || "") !== mc.lastRecording) {  // a recording started or ended: list again
    mc.lastRecording = s.recording || "";
    listRecordings();
  }
});
$("overrun-help").textContent = kOverrunHelp;

// ---------------------------------------------------------------------------------------------
// Scene: limits and units. Forces are micronewtons on a watch part, piconewtons on a trapped
// bead. The gauges span the platform's force limits when the server gives them (else the
// scene's full scale; the grip gauge 200 µN); the trap's contact gauge spans its escape force.
function forceUnit() {
  return mc.scene && mc.scene.kind === "optical-trap" ? {scale: 1e12, label: "pN"} : {scale: um, label: "µN"};
}
function contactFullScale() {
  const sc = mc.scene;
  if (!sc) return 50e-6;
  if (sc.kind !== "optical-trap" && isNum(sc.contact_force_limit_N) && sc.contact_force_limit_N > 0) return sc.contact_force_limit_N;
  return sc.force_full_scale_N;
}
function gripFullScale() {
  const sc = mc.scene;
  return sc && isNum(sc.grip_force_limit_N) && sc.grip_force_limit_N > 0 ? sc.grip_force_limit_N : 200e-6;
}
const fmtForce = (f, n) => (n * f.scale).toFixed(n * f.scale >= 100 ? 0 : 1) + " " + f.label;

listen("/platform/scene", (s) => {
  const first = !mc.scene || mc.scene.kind !== s.kind;
  mc.scene = s;
  // The speed scale spans what the server accepts (20 um/s for a bead, 1 mm/s for a part).
  const maxSpeed = Math.max(1, Math.round(s.max_speed_m_s * um));
  if (Number($("speed").max) !== maxSpeed) {
    $("speed").max = maxSpeed;
    if (Number($("speed").value) > maxSpeed) $("speed").value = maxSpeed;
    $("speed-out").textContent = $("speed").value + " µm/s";
  }
  const f = forceUnit(), optical = s.kind === "optical-trap";
  if (first) {
    setForceUnit(f, optical);
    $("forces-title").textContent = optical ? "Force on the probe bead" : "Forces on the gripper";
  }
  $("gripper").max = Math.round(s.max_opening_m * um);
  if (!mc.input.gripperTouched) {
    mc.input.gripper = s.max_opening_m;
    $("gripper").value = Math.round(s.max_opening_m * um);
    $("gripper-out").textContent = Math.round(s.max_opening_m * um) + " µm";
  }
  const contact = contactFullScale(), grip = gripFullScale();
  $("contact-gauge").max = contact * f.scale;
  $("contact-gauge").high = 0.8 * contact * f.scale;
  $("contact-limit").textContent = "/ " + fmtForce(f, contact) + (optical ? " escape" : " limit");
  for (const id of ["grip-gauge", "grip-vision-gauge"]) {
    $(id).max = grip * um;
    $(id).high = 0.8 * grip * um;
  }
  $("grip-limit").textContent = "/ " + fmtForce({scale: um, label: "µN"}, grip) + (isNum(s.grip_force_limit_N) ? " limit" : "");
  // The demo is the pick-and-place: a scene without it says why (absent field: available).
  const available = s.demo_available !== false;
  $("demo").disabled = !available;
  $("demo").title = available ? "Restart the scene with the scripted pick-and-place operator"
                              : "Demo unavailable: " + (s.demo_unavailable_reason || "not in this scene");
});

// ---------------------------------------------------------------------------------------------
// Feedback: force vector and gauges; the gamepad's rumble follows the high band of the contact
// force (the crossover's HF channel, computed by the server).
function drawForce(fv) {
  const c = $("force-vector"), g = c.getContext("2d"), r = c.width / 2;
  g.clearRect(0, 0, c.width, c.height);
  g.strokeStyle = "#3a4250";
  g.beginPath(); g.arc(r, r, r - 2, 0, 2 * Math.PI); g.stroke();
  const full = contactFullScale(), k = (r - 6) / full;
  const fx = clamp(fv[0], -full, full), fy = clamp(fv[1], -full, full);
  g.strokeStyle = "#ff9f43";
  g.lineWidth = 3;
  g.beginPath(); g.moveTo(r, r); g.lineTo(r + fx * k, r - fy * k); g.stroke();
  g.lineWidth = 1;
}
listen("/console/feedback", (p) => {
  mc.feedback = p;
  const [fx, fy, fz] = p.contact_N;
  const n = Math.hypot(fx, fy, fz), f = forceUnit();
  $("contact-gauge").value = n * f.scale;
  $("contact-out").textContent = fmtForce(f, n);
  $("grip-gauge").value = p.grip_N * um;
  $("grip-out").textContent = (p.grip_N * um).toFixed(1) + " µN";
  $("rumble-gauge").value = p.rumble;
  drawForce(p.contact_N);
  const pad = gamepad.pad;
  const now = performance.now();
  if (pad && pad.vibrationActuator && p.rumble > 0.02 && now - gamepad.lastRumble > 90) {
    gamepad.lastRumble = now;
    pad.vibrationActuator.playEffect("dual-rumble", {duration: 100, strongMagnitude: 0, weakMagnitude: Math.min(1, p.rumble)});
  }
});

// ---------------------------------------------------------------------------------------------
// The recordings in --out with their downloads and session reports (made on the first click).
function listRecordings() {
  fetch("/recordings" + location.search, {cache: "no-store"})
    .then((r) => (r.ok ? r.json() : {recordings: []}))
    .then((j) => {
      const table = $("recordings");
      table.innerHTML = "";
      if (!j.recordings.length) {
        table.innerHTML = "<tr><td>none yet: press Record</td></tr>";
        return;
      }
      for (const rec of j.recordings) {
        const tr = document.createElement("tr");
        const name = document.createElement("td"), size = document.createElement("td"), links = document.createElement("td");
        name.textContent = rec.name;
        if (rec.recovered) {  // left unfinished by a crash, recovered when serve started
          const tag = document.createElement("span");
          tag.className = "recovered";
          tag.title = "left unfinished by an earlier run (a crash); recovered up to its last whole second";
          tag.textContent = " recovered";
          name.append(tag);
        }
        size.textContent = rec.recording ? "" : (rec.bytes / 1e6).toFixed(1) + " MB";
        if (rec.recording) {
          links.textContent = "recording…";
        } else {
          const dl = document.createElement("a");
          dl.href = rec.url + location.search;  // the token, when the server needs one
          dl.textContent = "MCAP";
          dl.setAttribute("download", rec.name);
          const rep = document.createElement("a");
          rep.href = rec.report_url + location.search;
          rep.target = "_blank";
          rep.textContent = rec.report_ready ? "report" : "make report";
          links.append(dl);
          if (rec.csv_url) {  // the same samples as a CSV table
            const csv = document.createElement("a");
            csv.href = rec.csv_url + location.search;
            csv.textContent = "CSV";
            csv.setAttribute("download", rec.csv_url.split("/").pop());
            links.append(" · ", csv);
          }
          links.append(" · ", rep);
        }
        tr.append(name, size, links);
        table.append(tr);
      }
    })
    .catch(() => {});
}

connect();
