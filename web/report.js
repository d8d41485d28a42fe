// Renders the report described by the JSON in #report-data with uPlot (embedded above).
// Each figure container gets data-drawn="1" and data-points="N" once uPlot has drawn it;
// the browser test (tests/browser/report_renders.mjs) checks these and the canvas pixels.
(function () {
  "use strict";
  const doc = JSON.parse(document.getElementById("report-data").textContent);
  const root = document.getElementById("report");
  const palette = ["#1f77b4", "#d62728", "#2ca02c", "#ff7f0e", "#9467bd", "#8c564b", "#e377c2", "#17becf", "#7f7f7f", "#bcbd22"];

  function el(tag, attrs, text) {
    const e = document.createElement(tag);
    for (const k in attrs || {}) e.setAttribute(k, attrs[k]);
    if (text !== undefined) e.textContent = text;
    return e;
  }
  function axisTitle(a) { return a.unit ? a.label + " (" + a.unit + ")" : a.label; }
  function sameX(series) {
    const x0 = series[0].x;
    return series.every(s => s.x.length === x0.length && s.x.every((v, i) => v === x0[i])) &&
           x0.every((v, i) => i === 0 || v > x0[i - 1]);
  }

  // Tick labels: plain numbers in the readable range, engineering notation outside it
  // (micro-scale positions in metres would otherwise print as 0.000002).
  function tick(v) {
    if (v === null || v === undefined) return "";
    const a = Math.abs(v);
    if (a === 0) return "0";
    if (a >= 1e-3 && a < 1e5) return String(+v.toPrecision(6));
    return v.toExponential(Math.abs(+v.toExponential(2).split("e")[0] % 1) < 1e-9 ? 0 : 2).replace("e+", "e");
  }
  function axisOpts(a, vertical) {
    const o = { label: axisTitle(a) };
    if (!a.log) o.values = (u, vals) => vals.map(tick);
    if (vertical) o.size = (u, values) => 28 + 7 * Math.max(3, ...(values || []).map(s => String(s).length));
    return o;
  }

  // uPlot's log-axis tick generator slows to seconds per figure on values far from 1 (its
  // decimal rounding table stops near 1e-16), e.g. PSDs in m^2/Hz around 1e-21. Such a log
  // axis is drawn in units of a power of ten, shown in its title ("x 1e-21").
  function logExponent(values, log) {
    if (!log) return 0;
    let max = 0;
    for (const v of values) if (v > max && Number.isFinite(v)) max = v;
    if (max === 0 || (max >= 1e-6 && max < 1e9)) return 0;
    return Math.floor(Math.log10(max));
  }
  function scaled(arr, e) { return e === 0 ? arr : arr.map(v => v * Math.pow(10, -e)); }

  function plot(fig, container) {
    const ex = logExponent(fig.series.flatMap(s => s.x), fig.x.log);
    const ey = logExponent(fig.series.flatMap(s => s.y), fig.y.log);
    if (ex !== 0 || ey !== 0) {
      fig = Object.assign({}, fig, {
        x: ex ? Object.assign({}, fig.x, { unit: (fig.x.unit ? fig.x.unit + " " : "") + "x 1e" + ex }) : fig.x,
        y: ey ? Object.assign({}, fig.y, { unit: (fig.y.unit ? fig.y.unit + " " : "") + "x 1e" + ey }) : fig.y,
        series: fig.series.map(s => Object.assign({}, s, { x: scaled(s.x, ex), y: scaled(s.y, ey) })),
      });
    }
    const width = Math.min(1000, root.clientWidth - 20);
    const aligned = sameX(fig.series);
    const scaleOpts = a => (a.log ? { distr: 3, log: 10 } : {});
    const seriesOpts = fig.series.map((s, i) => ({
      label: s.name,
      stroke: palette[i % palette.length],
      width: s.points ? 0 : 1.5,
      points: s.points ? { show: true, size: 5, fill: palette[i % palette.length] } : { show: false },
      paths: s.points ? () => null : undefined,
      facets: aligned ? undefined : [{ scale: "x", auto: true }, { scale: "y", auto: true }],
    }));
    const opts = {
      title: fig.title,
      width: width,
      height: 340,
      mode: aligned ? 1 : 2,
      scales: { x: Object.assign({ time: false }, scaleOpts(fig.x)), y: scaleOpts(fig.y) },
      axes: [axisOpts(fig.x, false), axisOpts(fig.y, true)],
      series: [aligned ? { label: axisTitle(fig.x) } : {}].concat(seriesOpts),
      legend: { show: true },
      hooks: {
        draw: [u => {
          container.setAttribute("data-drawn", "1");
        }],
      },
    };
    let data;
    let points = 0;
    if (aligned) {
      data = [fig.series[0].x].concat(fig.series.map(s => s.y));
      points = fig.series.reduce((n, s) => n + s.y.length, 0);
    } else {
      data = [null].concat(fig.series.map(s => [s.x, s.y]));
      points = fig.series.reduce((n, s) => n + s.x.length, 0);
    }
    container.setAttribute("data-points", String(points));
    new uPlot(opts, data, container);
  }

  document.title = doc.title;
  root.appendChild(el("h1", {}, doc.title));
  const nav = el("nav");
  const ul = el("ul");
  nav.appendChild(ul);
  root.appendChild(nav);
  doc.sections.forEach((sec, si) => {
    const id = "sec-" + (si + 1);
    const li = el("li");
    li.appendChild(el("a", { href: "#" + id }, sec.title));
    ul.appendChild(li);
    const section = el("section", { id: id });
    section.appendChild(el("h2", {}, sec.title));
    (sec.text || "").split(/\n\s*\n/).filter(p => p.trim()).forEach(p => section.appendChild(el("p", {}, p)));
    if (sec.results.length) {
      const table = el("table", { class: "results" });
      sec.results.forEach(r => {
        const tr = el("tr");
        tr.appendChild(el("td", {}, r.name));
        tr.appendChild(el("td", { class: "v" }, r.value));
        tr.appendChild(el("td", {}, r.unit));
        table.appendChild(tr);
      });
      section.appendChild(table);
    }
    sec.figures.forEach(fig => {
      const box = el("div", { class: "figure", id: fig.id });
      const chart = el("div", { class: "chart" });
      box.appendChild(chart);
      if (fig.caption) box.appendChild(el("p", { class: "caption" }, fig.caption));
      const link = el("a", { href: fig.csv, class: "csv" }, "data: " + fig.csv);
      box.appendChild(link);
      section.appendChild(box);
      plot(fig, chart);
    });
    root.appendChild(section);
  });
  if (!doc.sections.length) nav.remove();
})();
