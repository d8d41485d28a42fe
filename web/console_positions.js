// Where the stage is and where it should go: the measured X/Y/Z readout (µm) and the rotary axis'
// θ (degrees, with 1 and 5 degree steps, when the scene has one), a go-to entry,
// step jog buttons (1, 10, 100 µm per axis) and saved positions (kept in the browser's
// localStorage, per scene kind). Each sets the command's goal, as click-to-go does; the server
// moves toward it only while the deadman is held, and the hint under the readout says so.
"use strict";

const kSteps = [-100, -10, -1, 1, 10, 100];  // µm
const kAxes = ["x", "y", "z"];
const fmtUm = (v) => (Math.abs(v) < 0.05e-6 ? 0 : v * um).toFixed(1);  // no "-0.0"

// A goal inside the stage's workspace (the server clamps too; clamping here keeps the goal the
// page draws and the one the loop follows the same).
function setGoal(goal) {
  const sc = mc.scene;
  mc.input.goal = goal.map((v, i) => (sc && Array.isArray(sc.workspace_min_m) && Array.isArray(sc.workspace_max_m)
                                          ? clamp(v, sc.workspace_min_m[i], sc.workspace_max_m[i]) : v));
}
mc.setGoal = setGoal;

// Steps add up from the pending goal, else from where the stage is told to be (its target).
function goalBase() {
  const t = mc.telemetry;
  if (mc.input.goal) return mc.input.goal.slice();
  return t ? [t.target_x_m, t.target_y_m, t.target_z_m] : null;
}

(function buildReadout() {
  for (const [axis, name] of kAxes.entries()) {
    const tr = document.createElement("tr");
    const th = document.createElement("th"), value = document.createElement("td"), jog = document.createElement("td");
    th.textContent = name.toUpperCase();
    value.id = "pos-" + name;
    value.className = "num";
    value.textContent = "—";
    jog.className = "jog";
    for (const step of kSteps) {
      const b = document.createElement("button");
      b.textContent = (step > 0 ? "+" : "−") + Math.abs(step);
      b.title = `${name} ${step > 0 ? "+" : "−"}${Math.abs(step)} µm (hold the deadman to move)`;
      b.dataset.axis = name;
      b.dataset.step = String(step);
      b.addEventListener("click", () => {
        const base = goalBase();
        if (!base) return;
        base[axis] += step * 1e-6;
        setGoal(base);
      });
      jog.append(b);
    }
    tr.append(th, value, jog);
    $("readout").append(tr);
  }
  // The rotary axis: its yaw in degrees; a step sets a goal from the pending one, else the target.
  const tr = document.createElement("tr"), th = document.createElement("th");
  const value = document.createElement("td"), jog = document.createElement("td");
  tr.id = "theta-row";
  tr.hidden = true;
  th.textContent = "θ";
  value.id = "pos-theta";
  value.className = "num";
  value.textContent = "—";
  jog.className = "jog";
  for (const step of [-5, -1, 1, 5]) {
    const b = document.createElement("button");
    b.textContent = (step > 0 ? "+" : "−") + Math.abs(step) + "°";
    b.title = `θ ${step > 0 ? "+" : "−"}${Math.abs(step)}° (hold the deadman to turn)`;
    b.addEventListener("click", () => {
      const t = mc.telemetry, sc = mc.scene;
      if (!t || !sc) return;
      const base = mc.input.thetaGoal ?? t.target_theta_rad;
      mc.input.thetaGoal = clamp(base + step * Math.PI / 180, sc.theta_min_rad, sc.theta_max_rad);
    });
    jog.append(b);
  }
  tr.append(th, value, jog);
  $("readout").append(tr);
})();

// Go to: X, Y, Z in µm; an empty field keeps that axis where the stage is told to be.
$("goto").addEventListener("submit", (e) => {
  e.preventDefault();
  const base = goalBase();
  if (!base) return;
  for (const [axis, name] of kAxes.entries()) {
    const text = $("goto-" + name).value.trim();
    if (text !== "" && Number.isFinite(Number(text))) base[axis] = Number(text) * 1e-6;
  }
  setGoal(base);
  document.activeElement.blur();  // the keyboard is the operator's again (Space: the deadman)
});
$("goto-here").addEventListener("click", () => {
  const t = mc.telemetry;
  if (!t) return;
  for (const name of kAxes) $("goto-" + name).value = fmtUm(t["measured_" + name + "_m"]);
});

// ---------------------------------------------------------------------------------------------
// Saved positions, per scene kind (a bead's positions mean nothing to a watch part).
const storageKey = () => "microcobot.positions." + (mc.scene ? mc.scene.kind : "none");
function loadPositions() {
  try {
    const list = JSON.parse(localStorage.getItem(storageKey()) || "[]");
    return Array.isArray(list) ? list.filter((p) => p && Array.isArray(p.m) && p.m.length === 3 && p.m.every(isNum)) : [];
  } catch (e) {  // storage disabled, or a value this page did not write
    return [];
  }
}
function storePositions(list) {
  try {
    localStorage.setItem(storageKey(), JSON.stringify(list));
  } catch (e) {
    note("saved positions: the browser refused to store them (" + e.message + ")");
  }
  showPositions();
}
function showPositions() {
  const table = $("saved");
  table.innerHTML = "";
  const list = loadPositions();
  if (!list.length) {
    table.innerHTML = "<tr><td class=\"dim\">no saved position</td></tr>";
    return;
  }
  list.forEach((p, i) => {
    const tr = document.createElement("tr");
    const name = document.createElement("td"), where = document.createElement("td"), buttons = document.createElement("td");
    name.textContent = p.name;
    where.className = "num";
    where.textContent = p.m.map(fmtUm).join(", ") + " µm";
    const go = document.createElement("button"), del = document.createElement("button");
    go.textContent = "Go";
    go.title = "Go there (hold the deadman to move)";
    go.addEventListener("click", () => setGoal(p.m.slice()));
    del.textContent = "✕";
    del.title = "Delete " + p.name;
    del.addEventListener("click", () => storePositions(loadPositions().filter((_, j) => j !== i)));
    buttons.append(go, del);
    tr.append(name, where, buttons);
    table.append(tr);
  });
}
$("save-position").addEventListener("click", () => {
  const t = mc.telemetry;
  if (!t) return;
  const list = loadPositions();
  const used = new Set(list.map((p) => p.name));
  let n = list.length + 1;
  while (used.has("P" + n)) n++;
  list.push({name: "P" + n, m: [t.measured_x_m, t.measured_y_m, t.measured_z_m]});
  storePositions(list);
});
let positionsScene = null;
listen("/platform/scene", (s) => {
  if (s.kind !== positionsScene) {
    positionsScene = s.kind;
    showPositions();
  }
});

// ---------------------------------------------------------------------------------------------
// The readout and what the goal is waiting for.
listen("/platform/telemetry", (t) => {
  for (const name of kAxes) {
    const v = t["measured_" + name + "_m"];
    $("pos-" + name).textContent = isNum(v) ? fmtUm(v) : "—";
  }
  const rotary = !!(mc.scene && mc.scene.theta_max_rad > mc.scene.theta_min_rad);
  $("theta-row").hidden = $("theta-controls").hidden = !rotary;
  if (rotary && isNum(t.measured_theta_rad)) {
    $("pos-theta").textContent = (t.measured_theta_rad * 180 / Math.PI).toFixed(3) + "°";
    // A goal reached is let go: the target stays there, and no stale goal outlives it.
    const g = mc.input.thetaGoal;
    if (g !== null && g !== undefined && Math.abs(t.target_theta_rad - g) < 1e-9) mc.input.thetaGoal = null;
  }
  const g = mc.input.goal, hint = $("goal-hint");
  let text, cls = "";
  if (!g) {
    text = "Goals move the stage only while the deadman is held (Space or the button).";
  } else {
    const d = Math.hypot(t.measured_x_m - g[0], t.measured_y_m - g[1], t.measured_z_m - g[2]);
    const where = `goal ${g.map(fmtUm).join(", ")} µm`;
    if (d < 2e-6) text = where + ": reached";
    else if (!mc.inControl) [text, cls] = [where + ": take control, then hold the deadman (Space) to move", "wait"];
    else if (!mc.input.deadman) [text, cls] = [where + ": hold the deadman (Space) to move", "wait"];
    else text = `${where}: moving, ${(d * um).toFixed(1)} µm to go`;
  }
  if (hint.textContent !== text) hint.textContent = text;
  hint.className = "hint " + cls;
});
