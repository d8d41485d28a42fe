// Live plots (uPlot): the last 10 s of telemetry. Each plot fills its panel (a ResizeObserver
// gives uPlot the panel's width) and its legend shows the latest sample unless the cursor is on
// the plot, where it shows the hovered one as usual.
"use strict";

const kWindow = 600;  // samples at the telemetry's 60 Hz
const kPlotHeight = 200;
const plots = [];

// series: [[telemetry key, label, dashed?], ...]; digits: the legend's decimals.
function makePlot(title, unit, scale, digits, series) {
  const div = document.createElement("div");
  div.className = "plot";
  const h = document.createElement("h3");
  h.textContent = title;
  div.append(h);
  $("plots").append(div);
  const colors = ["#4fa3ff", "#ff9f43", "#46c47e", "#c56cf0", "#ff5a5a", "#feca57"];
  const value = (u, v) => (v == null ? "--" : v.toFixed(digits));
  const opts = {
    width: Math.max(200, div.clientWidth - 16), height: kPlotHeight,
    scales: {x: {time: false}},
    axes: [{stroke: "#8a93a3", label: "t [s]"}, {stroke: "#8a93a3", label: unit}],
    series: [{label: "t", value: (u, v) => (v == null ? "--" : v.toFixed(2))}].concat(series.map((s, i) => (
      {label: s[1], value, stroke: colors[i % colors.length], width: 1.5, dash: s[2] ? [4, 4] : undefined}))),
  };
  const data = [[]].concat(series.map(() => []));
  const u = new uPlot(opts, data, div);
  const plot = {u, data, series, scale, title: h, div};
  // The panel's width, not the window's: the grid decides how wide a panel is.
  new ResizeObserver(() => {
    const width = Math.max(200, Math.floor(div.clientWidth - 16));
    if (width !== u.width) u.setSize({width, height: kPlotHeight});
  }).observe(div);
  plots.push(plot);
  return plot;
}
makePlot("Positions against targets", "µm", um, 1, [
  ["measured_x_m", "x"], ["target_x_m", "x target", true], ["measured_y_m", "y"], ["target_y_m", "y target", true],
  ["measured_z_m", "z"], ["target_z_m", "z target", true]]);
const forcePlot = makePlot("Forces on the gripper [µN]", "", um, 2, [
  ["contact_x_N", "contact x"], ["contact_y_N", "contact y"], ["contact_z_N", "contact z"], ["grip_force_N", "grip"]]);
makePlot("Drive amplitude", "V", 1, 2, [["u_x_V", "u x"], ["u_y_V", "u y"], ["u_z_V", "u z"]]);
makePlot("Loop tick", "µs", 1, 1, [["tick_us", "tick (wall clock)"], ["tick_cpu_us", "tick (loop thread CPU)"]]);

// Forces are micronewtons on a watch part, piconewtons on a trapped bead: the force plot's
// title and scale follow the scene (its samples so far are in the old unit: dropped).
function setForceUnit(f, optical) {
  forcePlot.title.textContent = optical ? "Force on the probe bead [pN]" : "Forces on the gripper [µN]";
  forcePlot.scale = f.scale;
  for (const a of forcePlot.data) a.length = 0;
}

listen("/platform/telemetry", (t) => {
  for (const p of plots) {
    p.data[0].push(t.t_s);
    p.series.forEach((s, i) => p.data[i + 1].push(isNum(t[s[0]]) ? t[s[0]] * p.scale : null));
    if (p.data[0].length > kWindow) for (const a of p.data) a.shift();
  }
});

// 10 redraws a second are enough for 10 s windows and spare the tablet's CPU.
setInterval(() => {
  for (const p of plots) {
    p.u.setData(p.data);
    const n = p.data[0].length;
    if (n > 0 && !(p.u.cursor.left >= 0)) p.u.setLegend({idx: n - 1});
  }
}, 100);
