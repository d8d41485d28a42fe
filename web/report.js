// Renders the report described by the JSON in #report-data with uPlot (embedded above).
// Each figure container gets data-drawn="1" and data-points="N" once uPlot has drawn it;
// the browser test (tests/browser/report_renders.mjs) checks these and the canvas pixels.
(function () {
  "use strict";
  const doc = JSON.parse(document.getElementById("report-data").textContent);
  const root = document.getElementById("report");
  // The box plots' first colours are also in tests/browser/report_renders.mjs (it counts each box's pixels).
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
  // (micro-scale positions in metres would otherwise print as 0.000002), with `digits`
  // significant digits at least.
  function tick(v, digits = 3) {
    if (v === null || v === undefined) return "";
    const a = Math.abs(v);
    if (a === 0) return "0";
    if (a >= 1e-3 && a < 1e5) return String(+v.toPrecision(Math.max(6, digits)));
    let [m, e] = v.toExponential(digits - 1).split("e");
    if (m.includes(".")) m = m.replace(/0+$/, "").replace(/\.$/, "");
    return m + "e" + e.replace("+", "");
  }
  // An axis' labels with as many digits as its neighbouring ticks need to read apart (a move of
  // 0.1 mm drawn to the nanometre spans 1e-4 to 1.0001e-4).
  function ticks(vals) {
    const shown = vals.filter(v => v !== null && v !== undefined);
    let digits = 3;
    while (digits < 15 && new Set(shown.map(v => tick(v, digits))).size < shown.length) ++digits;
    return vals.map(v => tick(v, digits));
  }
  // A log axis labels its decades; one that spans less than two decades also labels 2 and 5 of
  // each, so that every axis reads at least two values. Its other ticks stay unlabelled.
  function mantissa(v) { return +(v / Math.pow(10, Math.floor(Math.log10(v) + 1e-9))).toPrecision(3); }
  function logTicks(vals) {
    let keep = vals.map(v => v > 0 && mantissa(v) === 1);
    if (keep.filter(Boolean).length < 2) keep = vals.map(v => v > 0 && [1, 2, 5].includes(mantissa(v)));
    return vals.map((v, i) => (keep[i] ? tick(v) : ""));
  }
  // The labels drawn are also the container's data-x-ticks / data-y-ticks (the browser test
  // reads them: the canvas has no text to read).
  function axisOpts(a, vertical, container) {
    const o = { label: axisTitle(a) };
    o.values = (u, vals) => {
      const labels = a.log ? logTicks(vals) : ticks(vals);
      container.setAttribute(vertical ? "data-y-ticks" : "data-x-ticks", labels.filter(t => t !== "").join(" "));
      return labels;
    };
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
      // Unaligned series (uPlot's mode 2) have no x index range of their own: uPlot draws their
      // points only where a filter lists them, so each lists all of its points.
      points: s.points
        ? Object.assign({ show: true, size: 5, fill: palette[i % palette.length] },
                        aligned ? {} : { filter: (u, si) => u.data[si][0].map((_, k) => k) })
        : { show: false },
      paths: s.points ? () => null : undefined,
      facets: aligned ? undefined : [{ scale: "x", auto: true }, { scale: "y", auto: true }],
    }));
    const opts = {
      title: fig.title,
      width: width,
      height: 340,
      mode: aligned ? 1 : 2,
      scales: { x: Object.assign({ time: false }, scaleOpts(fig.x)), y: scaleOpts(fig.y) },
      axes: [axisOpts(fig.x, false, container), axisOpts(fig.y, true, container)],
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

  // Box plots (figures with "box": each series one group, its Tukey statistics computed by the
  // library, report/box_plot.h). uPlot has no box series: it draws the axes, grid and scales, and
  // a draw hook paints each group's box (IQR), median, whiskers (1.5 IQR) and outliers. The
  // container gets data-boxes (the groups painted, in order) for the browser test.
  function plotBox(fig, container) {
    const groups = fig.series;
    const n = groups.length;
    let lo = Infinity, hi = -Infinity;
    for (const g of groups) {
      lo = Math.min(lo, g.box.low, ...g.box.outliers);
      hi = Math.max(hi, g.box.high, ...g.box.outliers);
    }
    const pad = hi > lo ? 0.08 * (hi - lo) : Math.max(0.1 * Math.abs(hi), 1e-12);
    const xs = groups.map((g, i) => i + 1);
    function drawBoxes(u) {
      const ctx = u.ctx, px = uPlot.pxRatio;
      const X = v => u.valToPos(v, "x", true), Y = v => u.valToPos(v, "y", true);
      const half = Math.min(40 * px, 0.3 * (X(2) - X(1)));
      ctx.save();
      groups.forEach((g, i) => {
        const b = g.box, x = X(i + 1), color = palette[i % palette.length];
        ctx.strokeStyle = color;
        ctx.lineWidth = 1.5 * px;
        ctx.beginPath();  // whiskers and their caps
        for (const [from, to] of [[b.low, b.q1], [b.q3, b.high]]) {
          ctx.moveTo(x, Y(from));
          ctx.lineTo(x, Y(to));
        }
        for (const v of [b.low, b.high]) {
          ctx.moveTo(x - half / 2, Y(v));
          ctx.lineTo(x + half / 2, Y(v));
        }
        ctx.stroke();
        const top = Y(b.q3), height = Math.max(Y(b.q1) - top, 1 * px);
        ctx.globalAlpha = 0.25;
        ctx.fillStyle = color;
        ctx.fillRect(x - half, top, 2 * half, height);
        ctx.globalAlpha = 1;
        ctx.strokeRect(x - half, top, 2 * half, height);
        ctx.lineWidth = 3 * px;
        ctx.beginPath();
        ctx.moveTo(x - half, Y(b.median));
        ctx.lineTo(x + half, Y(b.median));
        ctx.stroke();
        ctx.lineWidth = 1.5 * px;
        for (const v of b.outliers) {
          ctx.beginPath();
          ctx.arc(x, Y(v), 3.5 * px, 0, 2 * Math.PI);
          ctx.stroke();
        }
      });
      ctx.restore();
      container.setAttribute("data-boxes", JSON.stringify(groups.map(g => g.name)));
      container.setAttribute("data-drawn", "1");
    }
    const opts = {
      title: fig.title,
      width: Math.min(1000, root.clientWidth - 20),
      height: 340,
      scales: { x: { time: false, range: [0.5, n + 0.5] }, y: { range: [lo - pad, hi + pad] } },
      axes: [
        { label: fig.x.label, splits: () => xs, values: () => groups.map(g => g.name + " (n = " + g.box.n + ")"),
          grid: { show: false } },
        axisOpts(fig.y, true, container),
      ],
      // The medians as an invisible series: uPlot needs one; the boxes are the hook's.
      series: [{}, { label: "median", paths: () => null, points: { show: false } }],
      legend: { show: false },
      hooks: { draw: [drawBoxes] },
    };
    container.setAttribute("data-points", String(groups.reduce((k, g) => k + g.box.n, 0)));
    new uPlot(opts, [xs, groups.map(g => g.box.median)], container);
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
      if (fig.box) plotBox(fig, chart); else plot(fig, chart);
    });
    root.appendChild(section);
  });
  if (!doc.sections.length) nav.remove();
})();
