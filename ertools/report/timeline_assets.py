"""The timeline page's stylesheet and script, inlined by :mod:`ertools.report.timeline_page`
(the page loads nothing: a Content-Security-Policy forbids it). ``CSS`` is a %-format string
(the colours come from :mod:`ertools.report.timeline_style`); ``SCRIPT`` is plain JavaScript.
"""

CSS = """
* { box-sizing: border-box; }
body { font: 14px/1.4 system-ui, -apple-system, "Segoe UI", Roboto, sans-serif; margin: 0;
       color: #1d2430; background: #fff; }
header { background: #14233c; color: #fff; padding: 14px 24px; }
header h1 { margin: 0 0 2px; font-size: 20px; font-weight: 600; }
header p { margin: 0; color: #c7d2e3; font-size: 13px; }
main { padding: 8px 24px 40px; }
h2 { font-size: 17px; margin: 24px 0 8px; border-bottom: 2px solid #d9dee5; }
.toolbar { display: flex; gap: 6px; align-items: center; margin: 8px 0; flex-wrap: wrap; }
.btn, button { display: inline-block; font: inherit; font-size: 13px; padding: 2px 10px;
       border: 1px solid #9aa5b4; border-radius: 4px; background: #f6f8fa; color: #1d2430;
       text-decoration: none; cursor: pointer; }
.btn:hover, button:hover { background: #e3e8ef; }
.btn.on { background: #14233c; color: #fff; border-color: #14233c; }
ul.sessions { list-style: none; padding: 0; margin: 4px 0; display: flex; flex-wrap: wrap;
       gap: 4px; max-height: 96px; overflow-y: auto; }
ul.legend { list-style: none; padding: 0; margin: 6px 0; display: flex; flex-wrap: wrap;
       gap: 4px 18px; font-size: 13px; }
.sw { display: inline-block; width: 22px; height: 12px; margin-right: 6px;
       vertical-align: -1px; border: 1px solid #555; }
.sw-problem { background: repeating-linear-gradient(45deg, #bbb 0 3px, #000 3px 4.5px);
       border: 2px solid %(edge)s; }
.sw-copy { background: #fff; border: 1.5px dashed #555; }
.sw-uncov { background: %(uncov)s; height: 4px; border: 0; vertical-align: 2px; }
.sw-session { background: %(session)s; border-color: #b8c2d0; }
.mk { display: inline-block; width: 14px; height: 14px; border-radius: 7px;
       background: %(marker)s; border: 1px solid #000; text-align: center; font-size: 10px;
       line-height: 12px; font-weight: 700; }
#tl-chart { border: 1px solid #d9dee5; overflow: hidden; user-select: none;
       touch-action: none; cursor: grab; }
#tl-chart.dragging { cursor: grabbing; }
#tl-svg { display: block; font-size: 11px; }
#tl-svg .lane-label { fill: #1d2430; }
#tl-svg .tick { stroke: #c9d1dc; stroke-width: 1; }
#tl-svg .tick-label { fill: #3b4657; }
#tl-svg .band { fill: %(session)s; stroke: #b8c2d0; stroke-width: 1; }
#tl-svg .band.on { fill: #d6e2f3; }
#tl-svg .slabel { fill: #14233c; font-weight: 600; }
#tl-svg .bar { stroke: #1d2430; stroke-width: 0.6; cursor: pointer; }
#tl-svg .bar.copy { fill: #fff !important; stroke-dasharray: 3 2; stroke-width: 1.5; }
#tl-svg .bar.problem { stroke: %(edge)s; stroke-width: 2; }
#tl-svg .hatch { fill: url(#tl-hatch); pointer-events: none; }
#tl-svg .uncov { fill: %(uncov)s; stroke: #000; stroke-width: 0.5; pointer-events: none; }
#tl-svg .mark circle { fill: %(marker)s; stroke: #000; stroke-width: 1; }
#tl-svg .mark text { font-size: 10px; font-weight: 700; text-anchor: middle; }
#tl-svg .mark { pointer-events: none; }
#tl-svg.selecting .bar:not(.sel):not(.linked) { opacity: 0.25; }
#tl-svg .bar.sel { stroke: #000; stroke-width: 3; }
#tl-svg .bar.linked { stroke: #000; stroke-width: 2.5; }
#tl-svg .link { stroke: #000; stroke-width: 1.5; stroke-dasharray: 4 3; fill: none; }
.muted { color: #5b6675; font-size: 13px; }
pre.details { background: #f6f8fa; border: 1px solid #d9dee5; padding: 8px; font-size: 12px;
       white-space: pre-wrap; word-break: break-all; min-height: 3em; }
.wrap { overflow-x: auto; }
table { border-collapse: collapse; font-size: 13px; margin: 4px 0; }
th, td { border: 1px solid #d9dee5; padding: 3px 8px; text-align: left; vertical-align: top; }
th { background: #f6f8fa; }
td { word-break: break-word; }
.ts { white-space: nowrap; }
#bags td:first-child { min-width: 18em; }
tr.problem td:first-child { border-left: 4px solid #000; }
ul.pl { margin: 0; padding-left: 16px; }
"""

# The chart. Built once from the JSON data; zoom and pan only rewrite the x and width of the
# existing elements (1,000 bars: well under a frame) and redraw the few tick marks.
SCRIPT = r"""
(function () {
  "use strict";
  var D = JSON.parse(document.getElementById("tl-data").textContent);
  var svg = document.getElementById("tl-svg");
  var box = document.getElementById("tl-chart");
  var NS = svg.namespaceURI;
  var LW = 20, TOP = 44, ROWH = 20, PAD = 6, RIGHT = 14, MINSPAN = 0.005;
  var CHAR = 7.0;  // width of a bold 11 px character, generously (labels must not collide)
  var bags = D.bags, sessions = D.sessions;
  var W = 800, H = 0, v0 = 0, v1 = 1, sel = null, hover = null;
  var dayS = Infinity, dayE = -Infinity;
  bags.forEach(function (b) { dayS = Math.min(dayS, b.s); dayE = Math.max(dayE, b.e); });
  if (!isFinite(dayS)) { dayS = 0; dayE = 1; }

  function el(tag, attrs, parent) {
    var e = document.createElementNS(NS, tag);
    for (var k in attrs) { e.setAttribute(k, attrs[k]); }
    if (parent) { parent.appendChild(e); }
    return e;
  }
  function title(e, text) { el("title", {}, e).textContent = text; }

  // Lanes: y of each lane from the rows it needs.
  var laneY = [], y = TOP;
  D.lanes.forEach(function (name, i) { laneY.push(y); y += D.rows[i] * ROWH + PAD; });
  H = y + 6;

  var defs = el("defs", {}, svg);
  var pat = el("pattern", {id: "tl-hatch", patternUnits: "userSpaceOnUse", width: 6,
                           height: 6, patternTransform: "rotate(45)"}, defs);
  el("line", {x1: 0, y1: 0, x2: 0, y2: 6, stroke: "#000", "stroke-width": 1.6,
              "stroke-opacity": 0.75}, pat);
  var clip = el("clipPath", {id: "tl-clip"}, defs);
  var clipRect = el("rect", {x: 0, y: 0, height: H}, clip);

  var gLanes = el("g", {"class": "lanes"}, svg);
  var stripes = [], labels = [], widest = 0;
  D.lanes.forEach(function (name, i) {
    stripes.push(el("rect", {x: 0, y: laneY[i], height: D.rows[i] * ROWH + PAD,
                             fill: i % 2 ? "#ffffff" : "#f7f9fb"}, gLanes));
    var short = name.length > 40 ? name.slice(0, 39) + "\u2026" : name;
    var t = el("text", {"class": "lane-label", y: laneY[i] + (D.rows[i] * ROWH + PAD) / 2 + 4,
                        "text-anchor": "end"}, gLanes);
    t.textContent = short; title(t, name);
    labels.push(t);
    // measured once (the labels never move), estimated where the page is not laid out
    var w = 0;
    try { w = t.getComputedTextLength(); } catch (e) { w = 0; }
    widest = Math.max(widest, w || short.length * 6.6);
  });
  LW = Math.max(90, Math.min(320, widest + 16));
  labels.forEach(function (t) { t.setAttribute("x", LW - 6); });
  var plot = el("g", {"clip-path": "url(#tl-clip)"}, svg);
  var gBands = el("g", {"class": "bands"}, plot);
  var gGrid = el("g", {"class": "grid"}, plot);
  var gBars = el("g", {"class": "bars"}, plot);
  var gLinks = el("g", {"class": "links"}, plot);
  var gLabels = el("g", {"class": "slabels"}, plot);  // above every band, never covered
  var dayLabel = el("text", {"class": "tick-label", x: 6, y: 14}, svg);

  var bands = sessions.map(function (s) {
    var r = el("rect", {"class": "band", y: TOP - 18, height: H - TOP + 18,
                        "data-session": s.index}, gBands);
    title(r, s.label);
    var t = el("text", {"class": "slabel", y: TOP - 6, "data-session": s.index}, gLabels);
    return {rect: r, text: t, s: s};
  });
  var barEls = bags.map(function (b, i) {
    var yb = laneY[b.lane] + PAD / 2 + b.row * ROWH + 1, h = ROWH - 6;
    var cls = "bar" + (b.problems.length ? " problem" : "") + (b.copy ? " copy" : "");
    var r = el("rect", {"class": cls, y: yb, height: h, "data-i": i, "data-kind": b.kind,
                        fill: D.colors[b.kind] || "#999"}, gBars);
    if (b.copy) { r.setAttribute("stroke", D.colors[b.kind] || "#999"); }
    title(r, b.tip);
    var o = {rect: r, y: yb, h: h, hatch: null, mark: null, unc: []};
    if (b.problems.length) {
      o.hatch = el("rect", {"class": "hatch", y: yb, height: h}, gBars);
      o.mark = el("g", {"class": "mark"}, gBars);
      el("circle", {r: 6, cx: 0, cy: 0}, o.mark);
      el("text", {x: 0, y: 3.5}, o.mark).textContent = "!";
    }
    b.uncovered.forEach(function () {
      o.unc.push(el("rect", {"class": "uncov", y: yb + h + 0.5, height: 3}, gBars));
    });
    return o;
  });

  var STEPS = [0.001, 0.002, 0.005, 0.01, 0.02, 0.05, 0.1, 0.2, 0.5, 1, 2, 5, 10, 15, 30,
               60, 120, 300, 600, 900, 1800, 3600, 7200, 10800, 21600, 43200, 86400,
               172800, 604800, 1209600, 2592000, 7776000, 31536000];
  function iso(t) { return new Date(Math.round((D.t0 + t) * 1000)).toISOString(); }
  function tickText(t, step) {
    var s = iso(t);
    if (step >= 86400) { return s.slice(0, 10); }
    if (step >= 60) { return s.slice(11, 16); }
    if (step >= 1) { return s.slice(11, 19); }
    return s.slice(11, 23);
  }
  function X(t) { return LW + (t - v0) * W / (v1 - v0); }
  function place(rect, a, b, minw) {
    var x = X(a), w = X(b) - x;
    if (w < minw) { x -= (minw - w) / 2; w = minw; }
    var lo = Math.max(x, LW - 20), hi = Math.min(x + w, LW + W + 20);
    if (hi < lo) { lo = -50; hi = -50; }
    rect.setAttribute("x", lo.toFixed(2));
    rect.setAttribute("width", (hi - lo).toFixed(2));
    return [lo, hi];
  }

  function render() {
    var began = window.performance.now();
    var span = v1 - v0;
    svg.setAttribute("data-view-start", (D.t0 + v0).toFixed(6));
    svg.setAttribute("data-view-end", (D.t0 + v1).toFixed(6));
    svg.setAttribute("data-px-per-s", (W / span).toPrecision(8));
    // ticks every ~110 px, on round clock times
    while (gGrid.firstChild) { gGrid.removeChild(gGrid.firstChild); }
    var want = span / Math.max(2, W / 110), step = STEPS[STEPS.length - 1];
    for (var i = 0; i < STEPS.length; i++) { if (STEPS[i] >= want) { step = STEPS[i]; break; } }
    var base = step >= 1 ? D.t0 % step : 0;
    var first = Math.ceil((v0 + base) / step) * step - base;
    var lastDay = iso(v0).slice(0, 10), labelEnd = -Infinity;
    for (var t = first, n = 0; t <= v1 && n < 200; t = first + (++n) * step) {
      var x = X(t);
      el("line", {"class": "tick", x1: x, x2: x, y1: 18, y2: H}, gGrid);
      var label = tickText(t, step), day = iso(t).slice(0, 10);
      if (day !== lastDay && step < 86400) { label = day + " " + label; }
      lastDay = day;
      // no label cut at the edge or over the previous one (the line is still drawn)
      if (x + 3 + label.length * 6.2 > LW + W || x < labelEnd + 6) { continue; }
      el("text", {"class": "tick-label", x: x + 3, y: 14}, gGrid).textContent = label;
      labelEnd = x + 3 + label.length * 6.2;
    }
    dayLabel.textContent = iso(v0).slice(0, 10) + " UTC";
    // session bands and their labels (the full label where it fits, "S3" where only that does)
    var right = -Infinity;
    bands.forEach(function (b) {
      var xs = place(b.rect, b.s.s, b.s.e, 3);
      var lo = Math.max(xs[0], LW), hi = Math.min(xs[1], LW + W);
      var mid = (lo + hi) / 2;
      var text = hi - lo >= b.s.label.length * CHAR + 8 ? b.s.label : "S" + b.s.index;
      var w = text.length * CHAR;
      var x0 = Math.max(LW + 2, Math.min(mid - w / 2, LW + W - w - 2));
      if (hi <= lo || x0 < right + 4) { b.text.textContent = ""; return; }
      b.text.textContent = text;
      b.text.setAttribute("x", x0.toFixed(1));
      right = x0 + w;
    });
    bags.forEach(function (b, i) {
      var o = barEls[i], xs = place(o.rect, b.s, b.e, 2);
      if (o.hatch) {
        o.hatch.setAttribute("x", xs[0].toFixed(2));
        o.hatch.setAttribute("width", (xs[1] - xs[0]).toFixed(2));
        var mx = Math.max(xs[0], LW) + 7;
        o.mark.setAttribute("transform", "translate(" + mx.toFixed(1) + "," +
                            (o.y + o.h / 2).toFixed(1) + ")");
        o.mark.setAttribute("visibility", xs[1] > LW && xs[0] < LW + W ? "visible" : "hidden");
      }
      b.uncovered.forEach(function (u, j) { place(o.unc[j], u[0], u[1], 2); });
    });
    drawLinks();
    var ro = document.getElementById("tl-readout");
    var a = iso(v0), b = iso(v1);
    ro.textContent = a.slice(0, 23).replace("T", " ") + " to " +
      (a.slice(0, 10) === b.slice(0, 10) ? b.slice(11, 23) : b.slice(0, 23).replace("T", " ")) +
      " UTC (" + fmtSpan(span) + " shown)";
    svg.setAttribute("data-render-ms", (window.performance.now() - began).toFixed(2));
  }
  function fmtSpan(s) {
    if (s >= 172800) { return (s / 86400).toFixed(1) + " days"; }
    if (s >= 7200) { return (s / 3600).toFixed(1) + " h"; }
    if (s >= 120) { return (s / 60).toFixed(1) + " min"; }
    if (s >= 1) { return s.toFixed(1) + " s"; }
    return (s * 1000).toFixed(1) + " ms";
  }
  function center(i) {
    var r = barEls[i].rect;
    return [parseFloat(r.getAttribute("x")) + parseFloat(r.getAttribute("width")) / 2,
            barEls[i].y + barEls[i].h / 2];
  }
  function drawLinks() {
    while (gLinks.firstChild) { gLinks.removeChild(gLinks.firstChild); }
    var i = sel !== null ? sel : hover;
    if (i === null) { return; }
    var a = center(i);
    bags[i].linked.forEach(function (j) {
      var b = center(j);
      el("line", {"class": "link", x1: a[0], y1: a[1], x2: b[0], y2: b[1]}, gLinks);
    });
  }
  function highlight() {
    var i = sel !== null ? sel : hover, linked = {};
    if (i !== null) { bags[i].linked.forEach(function (j) { linked[j] = true; }); }
    barEls.forEach(function (o, j) {
      o.rect.classList.toggle("sel", j === i);
      o.rect.classList.toggle("linked", !!linked[j]);
    });
    svg.classList.toggle("selecting", i !== null);
    drawLinks();
  }
  function select(i) {
    sel = i; highlight();
    document.getElementById("tl-details").textContent =
      i === null ? "Click a bar for its details." : bags[i].tip;
  }

  var frame = null;
  function setView(a, b, now) {
    var span = Math.min(Math.max(b - a, MINSPAN), Math.max((dayE - dayS) * 4, 60));
    var c = (a + b) / 2;
    c = Math.min(Math.max(c, dayS - span / 2), dayE + span / 2);
    v0 = c - span / 2; v1 = c + span / 2;
    if (now) { render(); return; }
    if (frame === null) {
      frame = window.requestAnimationFrame(function () { frame = null; render(); });
    }
  }
  function fitDay(now) {
    var m = Math.max((dayE - dayS) * 0.01, 0.5);
    setView(dayS - m, dayE + m, now);
    mark(null);
  }
  function zoomSession(idx, now) {
    var s = sessions.filter(function (x) { return x.index === idx; })[0];
    if (!s) { return false; }
    var m = Math.max((s.e - s.s) * 0.08, 0.5);
    setView(s.s - m, s.e + m, now);
    mark(idx);
    return true;
  }
  function mark(idx) {
    bands.forEach(function (b) { b.rect.classList.toggle("on", b.s.index === idx); });
    var links = document.querySelectorAll("a[data-session]");
    for (var k = 0; k < links.length; k++) {
      links[k].classList.toggle("on", +links[k].getAttribute("data-session") === idx);
    }
  }
  function applyHash(now) {
    var h = decodeURIComponent(window.location.hash.slice(1));
    if (h === "day") { fitDay(now); return; }
    var m = /^session=(\d+)$/.exec(h);
    if (m && zoomSession(+m[1], now)) { return; }
    m = /^bag=(\d+)$/.exec(h);
    if (m && bags[+m[1]]) {
      var b = bags[+m[1]];
      if (b.session === null || !zoomSession(b.session, now)) { fitDay(now); }
      select(+m[1]);
      return;
    }
    opening(now);
  }
  // Without a hash, the page opens on the sessions: the whole span when they fill a good part
  // of it, else the session with the most bags (a span of days is mostly gaps, and its
  // sessions would be slivers with overlapping labels); "fit day" shows the whole span.
  function opening(now) {
    var covered = sessions.reduce(function (a, s) { return a + (s.e - s.s); }, 0);
    if (!sessions.length || covered >= 0.2 * (dayE - dayS)) { fitDay(now); return; }
    var best = sessions.slice().sort(function (a, b) { return (b.n - a.n) || (a.s - b.s); })[0];
    zoomSession(best.index, now);
  }
  function resize() {
    W = Math.max(200, (box.clientWidth || 1000) - LW - RIGHT);
    svg.setAttribute("width", LW + W + RIGHT);
    svg.setAttribute("height", H);
    clipRect.setAttribute("x", LW);
    clipRect.setAttribute("width", W);
    stripes.forEach(function (s) { s.setAttribute("width", LW + W + RIGHT); });
  }

  // --- interaction --------------------------------------------------------------------
  function timeAt(clientX) {
    var r = svg.getBoundingClientRect();
    return v0 + (clientX - r.left - LW) / W * (v1 - v0);
  }
  svg.addEventListener("wheel", function (ev) {
    ev.preventDefault();
    var t = timeAt(ev.clientX);
    var f = Math.exp(ev.deltaY * (ev.deltaMode === 1 ? 0.05 : 0.0015));
    setView(t - (t - v0) * f, t + (v1 - t) * f);
  }, {passive: false});
  var drag = null;
  svg.addEventListener("pointerdown", function (ev) {
    drag = {x: ev.clientX, a: v0, b: v1, moved: false};
    // keep the drag when the pointer leaves the chart (not possible for every pointer)
    try { svg.setPointerCapture(ev.pointerId); } catch (e) { /* drag without capture */ }
  });
  svg.addEventListener("pointermove", function (ev) {
    if (!drag) {
      var i = ev.target.getAttribute && ev.target.getAttribute("data-i");
      var hv = i === null || i === undefined ? null : +i;
      if (hv !== hover) { hover = hv; if (sel === null) { highlight(); } }
      return;
    }
    var dx = ev.clientX - drag.x;
    if (Math.abs(dx) > 3) { drag.moved = true; box.classList.add("dragging"); }
    if (drag.moved) {
      var dt = -dx / W * (drag.b - drag.a);
      setView(drag.a + dt, drag.b + dt);
    }
  });
  svg.addEventListener("pointerup", function (ev) {
    var d = drag; drag = null; box.classList.remove("dragging");
    if (d && !d.moved) {
      var hit = document.elementFromPoint(ev.clientX, ev.clientY);
      var i = hit && hit.getAttribute ? hit.getAttribute("data-i") : null;
      select(i === null ? null : +i);
    }
  });
  svg.addEventListener("pointerleave", function () {
    if (hover !== null) { hover = null; if (sel === null) { highlight(); } }
  });
  document.addEventListener("click", function (ev) {
    var a = ev.target.closest ? ev.target.closest("a[data-session],a[data-day],a[data-bag]") : null;
    if (!a) { return; }
    if (a.hasAttribute("data-session")) { zoomSession(+a.getAttribute("data-session")); }
    else if (a.hasAttribute("data-bag")) { window.location.hash = a.getAttribute("href"); }
    else { fitDay(); }
  });
  document.querySelectorAll("button[data-zoom]").forEach(function (b) {
    b.addEventListener("click", function () {
      var f = +b.getAttribute("data-zoom"), c = (v0 + v1) / 2, h = (v1 - v0) * f / 2;
      setView(c - h, c + h);
    });
  });
  document.querySelectorAll("button[data-pan]").forEach(function (b) {
    b.addEventListener("click", function () {
      var d = (v1 - v0) * +b.getAttribute("data-pan");
      setView(v0 + d, v1 + d);
    });
  });
  document.addEventListener("keydown", function (ev) {
    if (ev.target && /^(INPUT|TEXTAREA|SELECT)$/.test(ev.target.tagName)) { return; }
    var c = (v0 + v1) / 2, h = (v1 - v0) / 2;
    if (ev.key === "+" || ev.key === "=") { setView(c - h / 2, c + h / 2); }
    else if (ev.key === "-") { setView(c - h * 2, c + h * 2); }
    else if (ev.key === "ArrowLeft") { setView(v0 - h / 2, v1 - h / 2); }
    else if (ev.key === "ArrowRight") { setView(v0 + h / 2, v1 + h / 2); }
    else if (ev.key === "0") { fitDay(); }
    else if (ev.key === "Escape") { select(null); }
  });
  window.addEventListener("hashchange", function () { applyHash(false); });
  window.addEventListener("resize", function () { resize(); render(); });

  resize();
  applyHash(true);
  svg.setAttribute("data-ready", "1");
})();
"""
