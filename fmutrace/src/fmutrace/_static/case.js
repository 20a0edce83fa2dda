/* A case page's interactive plots (uPlot): the inputs, then per compared
   signal its reference, result and band, and its deviation; the x axes
   kept in sync; framed on the first deviation on open. Data: window.fmutracePlot
   (the case's .plot.js). Zoom: drag a span, the mouse wheel or the buttons;
   pan: shift + wheel or the buttons; double click: the whole length. Reference and result are drawn the
   same way (values held until the next sample), so that equal samples draw one curve; a deviation that is
   0 throughout is said, not drawn; the legends show the values at the first deviation (else at the end)
   until the cursor is over a plot. */
(function () {
  "use strict";
  var data = window.fmutracePlot;
  var root = document.getElementById("plots");
  if (!data || !root || typeof uPlot === "undefined") { return; }
  var charts = [];
  var whole = null;  // [min, max] of every line's times
  var syncing = false;

  function finite(values) {
    return values.map(function (v) { return typeof v === "number" && isFinite(v) ? v : null; });
  }

  // lines [[times, values], ...] (each in time order) on one x axis: [x, y1, y2, ...], null where a line has no sample
  function aligned(lines) {
    var points = [];
    lines.forEach(function (line, k) {
      if (!line) { return; }
      var t = line[0], v = finite(line[1]);
      for (var i = 0; i < t.length; i++) { points.push([t[i], k, v[i], points.length]); }
    });
    points.sort(function (a, b) { return a[0] - b[0] || a[3] - b[3]; });
    var out = [points.map(function (p) { return p[0]; })];
    lines.forEach(function () { out.push(new Array(points.length).fill(null)); });
    points.forEach(function (p, i) { out[p[1] + 1][i] = p[2]; });
    lines.forEach(function (line) {
      if (line && line[0].length) {
        whole = whole ? [Math.min(whole[0], line[0][0]), Math.max(whole[1], line[0][line[0].length - 1])]
          : [line[0][0], line[0][line[0].length - 1]];
      }
    });
    return out;
  }

  // a long case's finer level: tiles of its span, each a script beside the page (<case>.plot.<k>.js),
  // loaded as the reader zooms in; a line drawn from the tiles loaded where there are some, else the overview
  var tiles = {}, pending = {}, refreshing = false;

  function overview(source) {
    return source[0] === "inputs" ? data.inputs[source[1]].line : data.signals[source[1]][source[2]];
  }

  function lineOf(source) {
    var base = overview(source), ks = Object.keys(tiles);
    if (!ks.length || !base) { return base; }
    var part = (data.span[1] - data.span[0]) / data.tiles, points = [];
    // the compared samples around the first deviation: at full resolution in the overview (the reference where
    // the comparison knew it there, not the inputs)
    var framed_here = source[0] === "signals" && (source[2] !== "reference" || data.signals[source[1]].reference_framed);
    var f = framed_here ? data.frame : null;
    function framed(t) { return !!f && t >= f[0] && t <= f[1]; }
    function loaded(t) { return !framed(t) && !!tiles[Math.min(data.tiles - 1, Math.floor((t - data.span[0]) / part))]; }
    for (var i = 0; i < base[0].length; i++) {
      if (!loaded(base[0][i])) { points.push([base[0][i], base[1][i], points.length]); }
    }
    ks.forEach(function (k) {
      var tile = tiles[k];
      var line = source[0] === "inputs" ? tile.inputs[source[1]] : tile.signals[source[1]][source[2]];
      if (!line) { return; }
      for (var j = 0; j < line[0].length; j++) {
        if (line[0][j] >= tile.from && line[0][j] < tile.to && !framed(line[0][j])) { points.push([line[0][j], line[1][j], points.length]); }
      }
    });
    points.sort(function (a, b) { return a[0] - b[0] || a[2] - b[2]; });
    return [points.map(function (p) { return p[0]; }), points.map(function (p) { return p[1]; })];
  }

  function refresh() {
    if (refreshing) { return; }
    refreshing = true;
    setTimeout(function () {
      refreshing = false;
      var min = charts[0].scales.x.min, max = charts[0].scales.x.max;
      syncing = true;
      charts.forEach(function (c) {
        c.setData(aligned(c.fmutraceSources.map(lineOf)), false);
        c.setScale("x", { min: min, max: max });
      });
      syncing = false;
      root.dataset.tilesLoaded = Object.keys(tiles).length;
    }, 0);
  }

  window.fmutraceTile = function (tile) {
    tiles[tile.k] = tile;
    delete pending[tile.k];
    refresh();
  };

  function refine(min, max) {
    if (!data.tiles || !root.dataset.tiles) { return; }
    var span = data.span[1] - data.span[0], part = span / data.tiles;
    if (max - min > span / 2) { return; }
    var first = Math.max(0, Math.floor((min - data.span[0]) / part));
    var last = Math.min(data.tiles - 1, Math.floor((max - data.span[0]) / part));
    for (var k = first; k <= last; k++) {
      if (tiles[k] || pending[k]) { continue; }
      pending[k] = true;
      var script = document.createElement("script");
      script.src = root.dataset.tiles + k + ".js";
      document.head.appendChild(script);
    }
  }

  function marker(u) {
    var at = data.first_deviation;
    if (at === null || at === undefined) { return; }
    var x = u.valToPos(at, "x", true);
    if (x < u.bbox.left || x > u.bbox.left + u.bbox.width) { return; }
    var ctx = u.ctx;
    ctx.save();
    ctx.strokeStyle = "#c00";
    ctx.lineWidth = 1.5 * uPlot.pxRatio;
    ctx.setLineDash([4 * uPlot.pxRatio, 3 * uPlot.pxRatio]);
    ctx.beginPath();
    ctx.moveTo(x, u.bbox.top);
    ctx.lineTo(x, u.bbox.top + u.bbox.height);
    ctx.stroke();
    ctx.restore();
  }

  function show(min, max) {
    if (!(max > min)) { return; }
    charts.forEach(function (c) { c.setScale("x", { min: min, max: max }); });
  }

  function scaled(u, key) {
    if (key !== "x" || syncing) { return; }
    syncing = true;
    var min = u.scales.x.min, max = u.scales.x.max;
    charts.forEach(function (c) { if (c !== u) { c.setScale("x", { min: min, max: max }); } });
    root.dataset.xmin = min;
    root.dataset.xmax = max;
    syncing = false;
    refine(min, max);
  }

  function width() { return Math.max(280, root.clientWidth - 4); }

  // a tick's text that keeps the scale however small or large the numbers (not the locale's 3 decimals)
  function ticks(u, splits) {
    return splits.map(function (v) {
      if (v === null) { return ""; }
      var x = Number(v.toPrecision(6));
      return x !== 0 && (Math.abs(x) < 1e-3 || Math.abs(x) >= 1e6) ? x.toExponential() : String(x);
    });
  }

  // a legend's value as it is (the shortest text that reads back to it), not rounded to the locale's 3 decimals
  function exactly(u, v) { return v === null || v === undefined ? "--" : String(v); }

  // the legend's values when the cursor is not over the plot: each line's sample nearest to the first deviation,
  // else to the end (the lines' samples have x entries of their own: a line has none at the others')
  function nearest(u, s, k) {
    for (var d = 0; d < u.data[0].length; d++) {
      if (k - d >= 0 && u.data[s][k - d] !== null) { return k - d; }
      if (k + d < u.data[0].length && u.data[s][k + d] !== null) { return k + d; }
    }
    return null;
  }

  function restingIndexes(u) {
    var xs = u.data[0], n = xs.length, at = data.first_deviation, k = n - 1;
    if (!n) { return null; }
    if (at !== null && at !== undefined) {
      k = 0;
      while (k < n - 1 && xs[k] < at) { k++; }
    }
    return u.series.map(function (_, s) { return s === 0 ? k : nearest(u, s, k); });
  }

  var resting = false;
  function rest(u) {
    if (resting || (u.legend.idx !== null && u.legend.idx !== undefined)) { return; }
    var idxs = restingIndexes(u);
    if (!idxs) { return; }
    resting = true;
    u.setLegend({ idxs: idxs });
    resting = false;
  }

  function chart(title, names, styles, sources, height, valueLabel) {
    var box = document.createElement("div");
    box.className = "plot";
    var h = document.createElement("h3");
    h.textContent = title;
    box.appendChild(h);
    root.appendChild(box);
    var series = [{ label: "t [s]", value: exactly }];
    names.forEach(function (name, k) {
      series.push(Object.assign({ label: name, spanGaps: true, width: 1.5, value: exactly }, styles[k]));
    });
    var bands = styles.some(function (s) { return s.band; }) ? [{ series: [names.length, names.length - 1], fill: "rgba(0,0,0,0.09)" }] : [];
    var options = {
      width: width(),
      height: height,
      series: series,
      bands: bands,
      scales: { x: { time: false } },
      axes: [{ label: "time [s]" }, { label: valueLabel || "", values: ticks, size: 72, space: 20 }],
      // (hovered: each line's nearest sample, not the null of another line's x)
      cursor: { sync: { key: "fmutrace" }, drag: { x: true, y: false }, hover: { skip: [null, undefined] } },
      hooks: { setScale: [scaled], draw: [marker], setLegend: [rest] }
    };
    var u = new uPlot(options, aligned(sources.map(lineOf)), box);
    rest(u);
    u.fmutraceSources = sources;
    u.over.addEventListener("wheel", function (e) {
      e.preventDefault();
      var min = u.scales.x.min, max = u.scales.x.max, span = max - min;
      if (e.shiftKey) {
        var by = span * 0.1 * Math.sign(e.deltaY || e.deltaX);
        show(min + by, max + by);
        return;
      }
      var at = u.posToVal(e.offsetX, "x"), f = e.deltaY < 0 ? 0.8 : 1.25;
      show(at - (at - min) * f, at + (max - at) * f);
    }, { passive: false });
    box.dataset.title = title;
    charts.push(u);
    return u;
  }

  function tools() {
    var bar = document.createElement("div");
    bar.className = "tools";
    function button(label, act) {
      var b = document.createElement("button");
      b.type = "button";
      b.textContent = label;
      b.addEventListener("click", act);
      bar.appendChild(b);
    }
    function scale() { return charts[0].scales.x; }
    button("zoom in", function () { var s = scale(), m = (s.min + s.max) / 2, h = (s.max - s.min) / 4; show(m - h, m + h); });
    button("zoom out", function () { var s = scale(), m = (s.min + s.max) / 2, h = s.max - s.min; show(m - h, m + h); });
    button("\u25C0 pan", function () { var s = scale(), d = (s.max - s.min) / 4; show(s.min - d, s.max - d); });
    button("pan \u25B6", function () { var s = scale(), d = (s.max - s.min) / 4; show(s.min + d, s.max + d); });
    button("whole length", function () { if (whole) { show(whole[0], whole[1]); } });
    if (data.frame) { button("first deviation", frame); }
    var hint = document.createElement("span");
    hint.className = "hint";
    hint.textContent = "drag: zoom to a span, wheel: zoom, shift + wheel: pan, double click: whole length";
    bar.appendChild(hint);
    root.appendChild(bar);
  }

  function frame() {
    var f = data.frame, pad = (f[1] - f[0]) * 0.05 || 1e-3;
    show(f[0] - pad, f[1] + pad);
  }

  // a held value (an input, the result) drawn as steps; but a long case's lines are envelopes (a column's
  // first, lowest, highest, last sample), which steps would draw as a staircase that is not there: straight
  function held(style) {
    if (!data.tiles) { style.paths = uPlot.paths.stepped({ align: 1 }); }
    return style;
  }

  tools();
  if (data.inputs.length) {
    chart("inputs", data.inputs.map(function (i) { return "input " + i.name; }),
      data.inputs.map(function (_, k) { return held({ stroke: ["#1f77b4", "#2ca02c", "#9467bd", "#8c564b"][k % 4] }); }),
      data.inputs.map(function (_, k) { return ["inputs", k]; }), 160);
  }
  data.signals.forEach(function (s, n) {
    var names = [s.name + " reference", s.name + " " + data.label];
    var styles = [held({ stroke: "#777" }), held({ stroke: "#e8710a" })];
    var lines = [["signals", n, "reference"], ["signals", n, "result"]];
    if (s.lower && s.upper) {
      names.push("lower", "upper");
      styles.push({ stroke: "#bbb", width: 1 }, { stroke: "#bbb", width: 1, band: true });
      lines.push(["signals", n, "lower"], ["signals", n, "upper"]);
    }
    var title = s.name + (s.criterion ? " (" + s.criterion + ")" : "");
    chart(title, names, styles, lines, 230).root.parentNode.dataset.signal = s.name;
    function zero(line) { return !line || line[1].every(function (v) { return v === 0; }); }
    var none = zero(s.deviation) && zero(s.back);
    if (none) {
      var box = document.createElement("div");
      box.className = "plot deviation-none";
      box.dataset.signal = s.name;
      var h = document.createElement("h3");
      h.textContent = s.name + ": deviation";
      var p = document.createElement("p");
      p.textContent = "none: " + data.deviation_label + " is 0 at every compared sample";
      box.appendChild(h);
      box.appendChild(p);
      root.appendChild(box);
      return;
    }
    var deviations = [s.name + " deviation"], strokes = [held({ stroke: "#d62728" })], sources = [["signals", n, "deviation"]];
    if (s.back) {  // a two-sided tube: the reference outside the tube around the result too
      deviations.push(s.name + ": " + data.back_label);
      strokes.push(held({ stroke: "#9467bd", dash: [5, 3] }));
      sources.push(["signals", n, "back"]);
    }
    chart(s.name + ": deviation", deviations, strokes, sources, 170, data.deviation_label)
      .root.parentNode.dataset.signal = s.name;
  });
  if (data.frame) { frame(); } else if (charts.length) { root.dataset.xmin = charts[0].scales.x.min; root.dataset.xmax = charts[0].scales.x.max; }
  window.addEventListener("resize", function () {
    charts.forEach(function (c) { c.setSize({ width: width(), height: c.height }); });
  });
  window.fmutraceCharts = charts;
}());
