// The supervised task (`serve --cell`): its steps with their autonomy, the
// current one highlighted, its status, and the operator's controls (start, pause, resume,
// confirm, take over, hand back, step done, skip) sent as /console/action task_*, and the batch's
// Next part (next_part) when serve has a batch. The rules
// (who may, what stops the stage, what a take-over re-takes) are the platform's; this panel
// presents the status's `task` and sends the actions. Hidden without a task.
"use strict";

const kTaskButtons = [
  // [id, label, action, title, enabled(task)]
  ["task-start", "Start", "task_start", "Start the automatic insertion", (t) => !t.started],
  ["task-pause", "Pause", "task_pause", "Hold the stage where it is (anyone may)", (t) => t.status === "running"],
  ["task-resume", "Resume", "task_resume", "Go on from where the stage is", (t) => t.status === "paused"],
  ["task-confirm", "Confirm", "task_confirm", "Let the waiting step start", (t) => t.status === "awaiting confirmation"],
  ["task-take-over", "Take over", "task_take_over", "Drive the stage yourself (deadman, joystick, click-to-go); the task waits",
   (t) => t.started && !["succeeded", "failed", "operator"].includes(t.status)],
  ["task-hand-back", "Hand back", "task_hand_back", "The task again: this step, re-planned from where the stage is",
   (t) => t.status === "operator" || t.status === "assisted"],
  ["task-step-done", "Step done", "task_step_done", "The task again: the next step (you did this one)",
   (t) => t.status === "operator" || t.status === "assisted"],
  ["task-skip", "Skip step", "task_skip", "Leave this step for the next one, from where the stage is",
   (t) => t.started && !["succeeded", "failed"].includes(t.status)],
  ["task-next-part", "Next part", "next_part", "The batch's next part: the scene rebuilt on it, its task waiting for Start",
   (t) => t.parts > 1 && (!t.started || ["succeeded", "failed"].includes(t.status))],
];

(function taskPanel() {
  const row = $("task-buttons");
  for (const [id, label, name, title] of kTaskButtons) {
    const b = document.createElement("button");
    b.id = id;
    b.textContent = label;
    b.title = title;
    b.disabled = true;
    b.addEventListener("click", () => {
      if (name === "task_take_over") handOverToTheConsole();
      action(name);
    });
    row.append(b);
  }
})();

// Taking over, and when the task ends: the page drops a pending click-to-go and puts its gripper
// slider where the gripper holds, and sends that, so that what it sends next moves nothing (the
// platform also re-takes the deadman and the slider before they count: a slider that never came
// back to the held opening would leave the gripper deaf).
function handOverToTheConsole() {
  mc.input.goal = null;
  const t = mc.telemetry;
  if (t && isNum(t.gripper_command_m)) setGripper(t.gripper_command_m);
}

function taskHint(t) {
  if (!t.started) return (mc.inControl ? "" : "Take control, then ") +
                         (mc.inControl ? "Press Start" : "press Start") + ": the robot picks the pin and inserts it; you supervise.";
  if (t.status === "running") return `The robot is in “${t.step}”.`;
  if (t.status === "paused" && t.heartbeat_gap) return "Paused while the console's commands are late: the stage holds; the task goes on when they return.";
  if (t.status === "paused")
    return t.supervisor_lost ? "Paused by the platform: control or the console's heartbeat was lost. Resume to go on."
                             : "Paused: the stage holds. Resume, take over or skip.";
  if (t.status === "awaiting confirmation") return `“${t.step}” waits for your Confirm (or Skip).`;
  if (t.status === "awaiting look") {
    const what = {slot: "the pin in its slot", bore: "the bore", held: "the pin in the fingers",
                  align: "the pin against its bore (the visual servo)", placed: "the pin placed"}[t.look] || "the pin";
    return `“${t.step}”: the cell's camera looks at ${what}; the stage holds.`;
  }
  if (t.status === "operator") return `You drive (${t.step}): hold the deadman to move. Hand back when ready.`;
  if (t.status === "assisted" && (t.step === "align" || t.step === "rotate"))
    return `You turn “${t.step}” with the dial, guided: hold the deadman and turn; a stop holds the fingers square, and the task goes on once they are.`;
  if (t.status === "assisted")
    return `You drive “${t.step}”, guided to its goal: hold the deadman and move towards it; the task goes on once you are there.`;
  const truth = t.inserted === true ? " — the pin is in its bore" : t.inserted === false ? " — the pin is not in its bore" : "";
  const again = t.parts > 1 ? "Next part for the batch's next, Restart scene for this one again." : "Restart scene for another cycle.";
  if (t.status === "succeeded") return `Succeeded in ${t.elapsed_s.toFixed(1)} s${truth}. ${again}`;
  return `Failed in “${t.step}”: ${t.failure || "no reason given"}${truth}. ${again}`;
}

let lastTaskKey = "", lastTaskEnded = null, lastOperatorDrives = false;
listen("/platform/status", (s) => {
  const t = s.task && typeof s.task === "object" ? s.task : null;
  $("task-group").hidden = !t;
  if (!t) return;
  const state = $("task-state");
  state.textContent = t.status;
  state.className = "pill " + ({running: "ok", succeeded: "ok", failed: "bad", paused: "warn",
                                "awaiting confirmation": "warn", "awaiting look": "ok", operator: "warn", assisted: "warn"}[t.status] || "");
  const looks = t.looks > 0 ? ` · camera ${t.looks_found}/${t.looks}` : "";
  const part = t.parts > 1 ? `part ${t.part + 1} of ${t.parts}` : "";
  $("task-info").textContent = [part, t.started ? `${t.elapsed_s.toFixed(1)} s · search tries ${t.search_tries}${looks}` : ""]
                                 .filter((x) => x).join(" · ");
  const key = JSON.stringify([t.step_index, t.status, t.steps]);
  if (key !== lastTaskKey) {  // the tree redrawn only when it changes
    lastTaskKey = key;
    const list = $("task-steps");
    list.innerHTML = "";
    t.steps.forEach((step, i) => {
      const li = document.createElement("li");
      const done = t.started && (i < t.step_index || t.status === "succeeded");
      li.className = i === t.step_index && t.started && t.status !== "succeeded" ? "current" : done ? "done" : "";
      const name = document.createElement("span"), level = document.createElement("span");
      name.textContent = (done ? "✓ " : "") + step.name;
      level.className = "autonomy " + step.autonomy;
      level.textContent = step.autonomy;
      li.append(name, level);
      list.append(li);
    });
  }
  const ended = ["succeeded", "failed"].includes(t.status);
  if (ended && lastTaskEnded === false) handOverToTheConsole();  // the console has the stage again
  lastTaskEnded = ended;
  // The robot drives again (an assisted step reached, a hand-back): the operator's pending
  // click-to-go was for their step; kept, it would pull the stage back there at the next take-over.
  const operatorDrives = ["operator", "assisted"].includes(t.status);
  if (lastOperatorDrives && !operatorDrives) mc.input.goal = null;
  // Handed a step (assisted, manual): the gripper slider where the gripper holds, as on Take over.
  if (!lastOperatorDrives && operatorDrives) handOverToTheConsole();
  lastOperatorDrives = operatorDrives;
  $("task-hint").textContent = taskHint(t);
  for (const [id, , name, , enabled] of kTaskButtons) {
    // Pausing needs no control (it only stops); the rest does.
    $(id).disabled = !enabled(t) || (!mc.inControl && name !== "task_pause");
  }
  mc.task = t;
});
