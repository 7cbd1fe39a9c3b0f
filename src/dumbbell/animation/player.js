// The dumbbell player: draws, in a canvas, what the GIF shows, from the picture that the
// GIF's painter draws (dumbbell/animation/picture.py): every box, colour, label and pixel
// factor comes from the data below; this script has none of its own. Text goes into the
// document as text (textContent), never as markup.
(function () {
  "use strict";
  const DOC = JSON.parse(document.getElementById("player-data").textContent);
  const P = DOC.picture, SPACE = DOC.kind === "space";
  const W = P.size[0], H = P.size[1], u = SPACE ? P.u : P.layout.u;
  const SCENE_W = SPACE ? P.scene_w : P.layout.scene_w;
  const FONT = '"DejaVu Sans", Verdana, "Segoe UI", Arial, sans-serif';
  const FPS = DOC.fps, T_END = DOC.t_end;
  const STACK_BELOW = SPACE ? P.factors.STACK_BELOW : P.factors.picture.STACK_BELOW;

  // --- the data ---------------------------------------------------------------------------
  const LITTLE = new Uint8Array(new Uint16Array([1]).buffer)[0] === 1;
  function decode(col) {
    if (!col) return null;
    const bin = atob(col.data), n = bin.length, bytes = new Uint8Array(n);
    for (let i = 0; i < n; i++) bytes[i] = bin.charCodeAt(i);
    const size = col.dtype === "f8" ? 8 : 4;
    if (!LITTLE) for (let i = 0; i < n; i += size) bytes.subarray(i, i + size).reverse();
    return size === 8 ? new Float64Array(bytes.buffer) : new Float32Array(bytes.buffer);
  }
  const runs = DOC.runs.map(function (r) {
    const run = { label: r.label, note: r.note, t: decode(r.t), A: decode(r.A), B: decode(r.B),
      E: {}, L: decode(r.L_cm), impacts: r.impacts || [], contacts: r.contacts || [] };
    for (const name in r.energy) run.E[name] = decode(r.energy[name]);
    run.n = run.t.length;
    let least = Infinity;
    for (let i = 1; i < run.n; i++) if (run.t[i] > run.t[i - 1]) least = Math.min(least, run.t[i] - run.t[i - 1]);
    run.spacing = isFinite(least) ? least : 1 / FPS;
    return run;
  });
  const SPACING = Math.min.apply(null, runs.map(function (r) { return r.spacing; }));
  const T_DECIMALS = SPACE ? P.t_decimals : Math.max(P.factors.world.TIME_DECIMALS, Math.min(6, Math.ceil(-Math.log10(SPACING) - 1e-9)));

  // The sample of a run nearest to time t (the earlier of two as near), as the GIF's frames.
  function nearest(run, t) {
    const ts = run.t, n = run.n;
    if (!(t > ts[0])) return 0;
    if (t >= ts[n - 1]) return n - 1;
    let lo = 0, hi = n - 1;
    while (hi - lo > 1) { const m = (lo + hi) >> 1; if (ts[m] < t) lo = m; else hi = m; }
    return Math.abs(ts[lo] - t) <= Math.abs(ts[hi] - t) ? lo : hi;
  }
  // The first sample at or after time t.
  function atOrAfter(run, t) {
    let lo = 0, hi = run.n;
    while (lo < hi) { const m = (lo + hi) >> 1; if (run.t[m] < t) lo = m + 1; else hi = m; }
    return Math.min(lo, run.n - 1);
  }

  // --- numbers as the GIF prints them ------------------------------------------------------
  // Python's f"{round(v, d) + 0.0:.{d}f}": floor(v 10^d + 0.5) with the point put back. The
  // page's numbers were chosen when it was written so that this prints each as Python does.
  function fixed(v, d, sign) {
    if (!isFinite(v)) return "n/a";
    const n = Math.floor(v * Math.pow(10, d) + 0.5);
    let s = Math.abs(n).toString();
    if (d > 0) { while (s.length < d + 1) s = "0" + s; s = s.slice(0, s.length - d) + "." + s.slice(s.length - d); }
    return (n < 0 ? "-" : sign === "+" ? "+" : "") + s;
  }
  const energyText = function (v) { return fixed(v, P.bars ? P.bars.scale.decimals : 2); };

  // --- the canvas --------------------------------------------------------------------------
  const canvas = document.getElementById("view");
  const ctx = canvas.getContext("2d", { alpha: false });
  canvas.width = W; canvas.height = H;
  let scale = 1, stacked = false, background = null;
  // The panels: the whole frame, or (a narrow window) the scene above the energy panel.
  function panels() {
    if (!stacked) return [{ src: [0, 0, W, H], at: [0, 0] }];
    const sw = SCENE_W, ew = W - sw, lw = Math.max(sw, ew);
    return [{ src: [0, 0, sw, H], at: [(lw - sw) / 2, 0] }, { src: [sw, 0, W, H], at: [(lw - ew) / 2, H] }];
  }
  function logicalSize() { return stacked ? [Math.max(SCENE_W, W - SCENE_W), 2 * H] : [W, H]; }

  const capCache = {};
  function font(px, bold) { return (bold ? "bold " : "") + px + "px " + FONT; }
  function cap(f) {
    if (!(f in capCache)) {
      ctx.save(); ctx.font = f; const m = ctx.measureText("0"); ctx.restore();
      capCache[f] = m.actualBoundingBoxAscent || parseFloat(f.replace(/^bold /, "")) * 0.73;
    }
    return capCache[f];
  }
  // Text anchored as the GIF's glyphs are: l/m/r, then m (middle of digits), t (top of
  // digits) or s (baseline).
  function text(c, s, x, y, anchor, f, colour) {
    c.font = f; c.fillStyle = colour;
    c.textAlign = { l: "left", m: "center", r: "right" }[anchor[0]];
    c.textBaseline = "alphabetic";
    const k = cap(f);
    c.fillText(s, x, { m: y + k / 2, t: y + k, s: y }[anchor[1]]);
  }
  function line(c, pts, colour, width) {
    c.beginPath(); c.moveTo(pts[0][0], pts[0][1]);
    for (let i = 1; i < pts.length; i++) c.lineTo(pts[i][0], pts[i][1]);
    c.strokeStyle = colour; c.lineWidth = width; c.stroke();
  }
  function rect(c, x0, y0, x1, y1, colour) { c.fillStyle = colour; c.fillRect(x0, y0, x1 - x0, y1 - y0); }
  const state = { t: 0, playing: false, speed: 1, loop: true, run: 0, last: null };
  const stats = { frames: 0, drawMs: [], playedFrames: 0 };

  // --- what a scene's frame shows (the picture of animation/picture.py) -----------------------
  function sceneDrawer() {
    const F = P.factors, C = P.colours, L = P.layout;
    const FW = F.world, FB = F.bars, FS = F.strip, FG = F.glyphs, SS = F.backdrop.SS, GHOST = F.picture.GHOST;
    const fNote = font(Math.round(FG.NOTE_PX * u)), fText = font(Math.max(8, Math.round(FG.TEXT_PX * u)));
    const fSmallNote = font(Math.max(8, Math.round(FG.NOTE_PX * u)));
    const fTime = font(Math.max(9, Math.round(FG.TIME_PX * u)), true);
    const fLetter = font(Math.max(8, Math.round(FG.NOTE_PX * u)), true);

    // --- what is drawn once: floor, ruler, legends, the strip's frame --------------------------
    function drawStatic(c) {
      rect(c, 0, 0, W, H, C.white);
      const wd = P.world;
      if (wd.floor_y !== null) {
        const lw = Math.round(FW.FLOOR_LINE * u * SS) / SS;
        rect(c, 0, wd.floor_y, L.scene_w, H, C.floor);
        line(c, [[0, wd.floor_y + lw / 2], [L.scene_w, wd.floor_y + lw / 2]], C.grey, lw);
      }
      const rx = L.ruler_x, ru = wd.ruler;
      line(c, [[rx, ru[0][0]], [rx, ru[ru.length - 1][0]]], C.grey, 1);
      for (const [y, label] of ru) {
        line(c, [[rx - FW.RULER_TICK * u, y], [rx, y]], C.grey, 1);
        text(c, label, rx - FW.RULER_LABEL * u, y, "rm", fNote, C.grey);
      }
      text(c, FW.RULER_NAME, FW.RULER_TITLE[0] * u, H - FW.RULER_TITLE[1] * u, "ls", fNote, C.grey);
      const edge = F.layout.EDGE * u;
      line(c, [[L.scene_w, edge], [L.scene_w, H - edge]], C.light, 1);
      const B = P.bars, [bx0, by0] = B.box;
      text(c, FB.TITLE, bx0, by0, "lt", font(Math.round(FG.TITLE_PX * u), true), C.ink);
      if (B.note) text(c, B.note, bx0 + FB.NOTE_X * u, by0 + u, "lt", font(Math.round(FG.SMALL_PX * u)), C.grey);
      const sw = Math.round(FB.SWATCH * u), fName = font(Math.round(FG.TEXT_PX * u));
      for (const [name, top, bot] of B.rows) {
        const mid = (top + bot) / 2;
        rect(c, bx0, mid - sw / 2, bx0 + sw, mid + sw / 2, C.terms[name] || C.grey);
        text(c, name, bx0 + sw + FB.SWATCH_GAP * u, mid, "lm", fName, C.ink);
      }
      line(c, [[B.zero + 0.5, B.rows[0][1] - FB.ZERO_OVERHANG], [B.zero + 0.5, B.rows[B.rows.length - 1][2] + FB.ZERO_OVERHANG]], C.grey, 1);
      const S = P.strip;
      if (S) {
        const [sx0, sy0, sx1, sy1] = S.box;
        c.strokeStyle = C.light; c.lineWidth = 1; c.strokeRect(sx0 + 0.5, sy0 + 0.5, sx1 - sx0, sy1 - sy0);
        for (const [v, label] of S.ticks) text(c, label, sx0 - FS.LABEL_GAP * u, stripY(v), "rm", fNote, C.grey);
        text(c, FS.ENERGY_AXIS, sx0 - FS.LABEL_GAP * u, sy0 - FS.LABEL_GAP * u, "rs", fNote, C.grey);
        text(c, FS.TIME_AXIS, sx0 - FS.LABEL_GAP * u, sy1 + FS.LABEL_GAP * u, "rt", fNote, C.grey);
      }
    }

    // --- the world -----------------------------------------------------------------------------
    function px(x, y) { return [L.ox + x * L.s, L.oy - y * L.s]; }
    function zigzag(p0, p1, amp, coils) {
      const ax = p1[0] - p0[0], ay = p1[1] - p0[1], length = Math.hypot(ax, ay);
      if (length === 0) return [p0, p1];
      const nx = -ay / length * amp, ny = ax / length * amp, lead = FW.LEAD;
      const pts = [p0, [p0[0] + ax * lead, p0[1] + ay * lead]];
      for (let i = 0; i < 2 * coils; i++) {
        const f = lead + (1 - 2 * lead) * (i + 0.5) / (2 * coils), s = i % 2 === 0 ? 1 : -1;
        pts.push([p0[0] + ax * f + s * nx, p0[1] + ay * f + s * ny]);
      }
      pts.push([p0[0] + ax * (1 - lead), p0[1] + ay * (1 - lead)], p1);
      return pts;
    }
    function axisAngle(pa, pb) { return Math.atan2(pa[0] - pb[0], pb[1] - pa[1]) * 180 / Math.PI; }
    function onDisc(at, half, centre, radius) {
      const dx = Math.max(Math.abs(at[0] - centre[0]) - half[0], 0), dy = Math.max(Math.abs(at[1] - centre[1]) - half[1], 0);
      return dx * dx + dy * dy < radius * radius;
    }
    function letterAt(p, r, other, pc, out, floorY, half) {
      const reach = Math.max(Math.hypot(p[0] - pc[0], p[1] - pc[1]) + r + FW.LETTER_GAP * u, FW.LABEL_CLEAR * u);
      let lx = pc[0] + out[0] * reach, ly = Math.min(pc[1] + out[1] * reach, floorY - FW.LETTER_GAP * u);
      if (onDisc([lx, ly], half, p, r + u)) {
        const side = p[0] >= other[0] ? 1 : -1;
        lx = p[0] + side * (r + FW.LETTER_GAP * u); ly = Math.min(p[1], floorY - FW.LETTER_GAP * u);
      }
      return [lx, ly];
    }
    function drawDumbbell(c, run, j, ghost, impact) {
      const ax = run.A[2 * j], ay = run.A[2 * j + 1], bx = run.B[2 * j], by = run.B[2 * j + 1];
      if (!(isFinite(ax) && isFinite(ay) && isFinite(bx) && isFinite(by))) return;
      const wd = P.world, pa = px(ax, ay), pb = px(bx, by), [ra, rb] = wd.radius_px;
      const twoD = wd.dimensions === 2, w = wd.weight_a;
      const pc = [w * pa[0] + (1 - w) * pb[0], w * pa[1] + (1 - w) * pb[1]];
      const floorY = wd.floor_y === null ? Infinity : wd.floor_y;
      c.save(); c.globalAlpha = ghost ? GHOST : 1; c.lineJoin = "round"; c.lineCap = "butt";
      if (ghost) c.setLineDash([3, 2]);
      if (twoD) {
        const dx = pa[0] - pb[0], dy = pa[1] - pb[1], length = Math.hypot(dx, dy);
        if (length > 0) {
          const th = axisAngle(pa, pb), ex = dx / length, ey = dy / length;
          const reach = Math.max(length / 2 + FW.AXIS_REACH * u, FW.AXIS_MIN * u), rv = FW.ARC * u;
          line(c, [[pc[0] - ex * reach, pc[1] - ey * reach], [pc[0] + ex * reach, pc[1] + ey * reach]], C.light, 1);
          line(c, [pc, [pc[0], pc[1] - rv * 1.25]], C.grey, 1);
          const a0 = Math.min(-90, -90 + th) * Math.PI / 180, a1 = Math.max(-90, -90 + th) * Math.PI / 180;
          c.beginPath(); c.arc(pc[0], pc[1], rv, a0, a1); c.strokeStyle = C.grey;
          c.lineWidth = Math.max(1, Math.round(FW.ARC_LINE * u * SS)) / SS; c.stroke();
        }
      }
      if (impact && wd.floor_y !== null) {
        const low = pa[1] > pb[1] ? pa : pb, y = wd.floor_y;
        line(c, [[low[0] - FW.IMPACT_MARK * u, y], [low[0] + FW.IMPACT_MARK * u, y]], C.black, Math.round(FW.IMPACT_LINE * u * SS) / SS);
        text(c, FW.IMPACT_WORD_TEXT, low[0], y + FW.IMPACT_GAP * u, "mt", fSmallNote, C.ink);
      }
      if (wd.link === "rod") line(c, [pa, pb], C.spring, Math.round(FW.ROD_LINE * u * SS) / SS);
      else if (wd.link === "spring") line(c, zigzag(pb, pa, wd.amp, FW.COILS), C.spring, Math.max(2, Math.round(FW.ZIGZAG_LINE * u * SS)) / SS);
      else line(c, [pa, pb], C.light, 1);
      const outline = Math.max(1, Math.round(FW.OUTLINE * u * SS)) / SS;
      const dist = Math.hypot(pa[0] - pb[0], pa[1] - pb[1]);
      const e = twoD && dist > 0 ? [(pa[0] - pb[0]) / dist, (pa[1] - pb[1]) / dist] : [0, 0];
      for (const [p, r, name, sign] of [[pa, ra, "A", 1], [pb, rb, "B", -1]]) {
        c.beginPath(); c.arc(p[0], p[1], r - outline / 2, 0, 2 * Math.PI);
        c.fillStyle = C.terms[name]; c.fill(); c.strokeStyle = C.ink; c.lineWidth = outline; c.stroke();
        if (ghost) continue;
        if (e[0] || e[1]) {
          c.font = fLetter;
          const half = [c.measureText(name).width / 2, cap(fLetter) / 2];
          const at = letterAt(p, r, name === "A" ? pb : pa, pc, [sign * e[0], sign * e[1]], floorY, half);
          text(c, name, at[0], at[1], "mm", fLetter, C.ink);
        } else {
          text(c, name, p[0] + r + FW.LETTER_GAP_1D * u, p[1], "lm", fLetter, C.ink);
        }
      }
      const rc = FW.CM_RADIUS * u;
      c.setLineDash([]);
      c.beginPath(); c.arc(pc[0], pc[1], rc - outline / 2, 0, 2 * Math.PI); c.fillStyle = C.white; c.fill();
      c.strokeStyle = C.black; c.lineWidth = outline; c.stroke();
      for (const [a0, a1] of [[Math.PI, 1.5 * Math.PI], [0, 0.5 * Math.PI]]) {
        c.beginPath(); c.moveTo(pc[0], pc[1]); c.arc(pc[0], pc[1], rc, a0, a1); c.closePath(); c.fillStyle = C.black; c.fill();
      }
      c.restore();
    }
    function drawTime(c, run, j) {
      text(c, "t = " + run.t[j].toFixed(T_DECIMALS) + " s", FW.TIME_AT * u, FW.TIME_AT * u, "lt", fTime, C.ink);
      if (P.world.dimensions !== 2) return;
      const ax = run.A[2 * j], ay = run.A[2 * j + 1], bx = run.B[2 * j], by = run.B[2 * j + 1];
      if (![ax, ay, bx, by].every(isFinite) || (ax === bx && ay === by)) return;
      const th = axisAngle(px(ax, ay), px(bx, by)), deg = Math.round(th);
      text(c, FW.ANGLE_TEXT[0] + (deg < 0 ? "-" : "+") + Math.abs(deg) + FW.ANGLE_TEXT[1], FW.TIME_AT * u, FW.ANGLE_AT * u, "lt", fSmallNote, C.grey);
    }

    // --- the energy bars ---------------------------------------------------------------------
    function barX(v) { return P.bars.zero + v * P.bars.px_per_j; }
    function span(c, a, b, top, bot, colour) {
      if (!(isFinite(a) && isFinite(b))) return;
      const x0 = Math.round(barX(a)), x1 = Math.round(barX(b));
      if (x1 > x0) rect(c, x0, top, x1, bot, colour);
    }
    // The least and largest value of each term since the previous frame (1/fps before).
    function sincePrevious(run, j, name) {
      const v = run.E[name], j0 = nearest(run, run.t[j] - 1 / FPS);
      let lo = v[j], hi = v[j];
      for (let i = j0; i < j; i++) { if (v[i] < lo) lo = v[i]; if (v[i] > hi) hi = v[i]; }
      return [lo, hi];
    }
    function drawBars(c, run, j) {
      const B = P.bars;
      for (const [name, top, bot] of B.rows) {
        const e = run.E[name][j];
        if (name === "E") {
          let x = 0;
          for (const term of B.terms) {
            const v = run.E[term][j];
            if (v > 0 && isFinite(v)) { span(c, x, x + v, top, bot, C.terms[term]); x += v; }
          }
          if (run.E.E_lost && run.E.E_lost[j] > 0) {
            const inset = Math.min(FB.LOST_INSET, Math.floor((bot - top - 1) / 2));
            span(c, x, x + run.E.E_lost[j], top + inset, bot - inset, C.tints.E_lost);
          }
          if (isFinite(e)) {
            const xm = Math.round(barX(e)), w = Math.max(3, Math.round(FB.MARKER * u));
            rect(c, xm - 1, top - 3, xm + 1, bot + 3, C.terms.E);
            c.beginPath(); c.moveTo(xm - w, top - 3 - w); c.lineTo(xm + w, top - 3 - w); c.lineTo(xm, top - 3); c.closePath();
            c.fillStyle = C.terms.E; c.fill();
          }
        } else {
          const [lo, hi] = sincePrevious(run, j, name), ink = C.terms[name] || C.grey;
          span(c, lo > 0 ? Math.min(lo, 0) : lo, hi, top, bot, C.tints[name] || ink);
          span(c, Math.min(e, 0), Math.max(e, 0), top, bot, ink);
        }
        text(c, energyText(e), B.box[2], (top + bot) / 2, "rm", fText, C.ink);
      }
      if (run.L && isFinite(run.L[j])) {
        const below = B.rows[B.rows.length - 1][2];
        const limit = P.strip ? P.strip.box[1] - Math.round(FB.MOMENTUM_GAP * u) : H - Math.round(FB.MOMENTUM_EDGE * u);
        if (limit - below >= FB.MOMENTUM_ROOM * u) {
          const value = fixed(run.L[j], 4, "+");
          let s = FB.MOMENTUM_TEXT[0] + value + FB.MOMENTUM_TEXT[1] + FB.MOMENTUM_TEXT[2];
          c.font = fSmallNote;
          if (c.measureText(s).width > B.box[2] - B.box[0]) s = FB.MOMENTUM_TEXT[0] + value + FB.MOMENTUM_TEXT[1];
          text(c, s, B.box[2], (below + limit) / 2, "rm", fSmallNote, C.ink);
        }
      }
    }

    // --- the strip -----------------------------------------------------------------------------
    function stripY(v) {
      const S = P.strip, [, sy0, , sy1] = S.box, pad = FS.PAD * u, lo = S.scale.lo, hi = S.scale.hi;
      return sy1 - pad - (sy1 - sy0 - 2 * pad) * (v - lo) / (hi - lo);
    }
    // Per run, each term drawn as a band: its least and largest row in each tape column.
    function bandsOf(run, k) {
      const S = P.strip, out = {};
      for (const name in P.bands[k] || {}) {
        if (!P.bands[k][name]) continue;
        const lo = new Float32Array(S.tape_w).fill(NaN), hi = new Float32Array(S.tape_w).fill(NaN), v = run.E[name];
        for (let i = 0; i < run.n; i++) {
          const col = Math.floor(run.t[i] * S.px_per_s), y = stripY(v[i]);
          if (!(col >= 0 && col < S.tape_w) || !isFinite(y)) continue;
          if (!(lo[col] <= y)) lo[col] = y;
          if (!(hi[col] >= y)) hi[col] = y;
        }
        out[name] = [lo, hi];
      }
      return out;
    }
    runs.forEach(function (run, k) { run.bands = P.strip ? bandsOf(run, k) : {}; run.pieces = new Map(); });
    // The tape: a run's whole strip (grid, ticks, impacts, curves, contacts) at the strip's
    // time scale, drawn in pieces of TAPE_CHUNK columns when first needed, as the GIF does;
    // a frame copies the window it shows. Tape x: column (t * px_per_s); y: from tape_y.
    function drawTape(c, run, c0, c1) {
      const S = P.strip, pps = S.px_per_s, edge = S.box[3] - S.tape_y;
      const X = function (tt) { return tt * pps - c0; };
      const t0 = (c0 - 2) / pps, t1 = (c1 + 2) / pps;
      rect(c, 0, 0, c1 - c0, S.tape_h, C.white);
      for (const [v] of S.ticks) { const y = Math.round(stripY(v) - S.tape_y - 0.5); rect(c, 0, y, c1 - c0, y + 1, C.grid); }
      rect(c, 0, edge, c1 - c0, edge + 1, C.light);
      for (const [tk] of S.time_ticks) {
        if (tk < t0 || tk > t1) continue;
        const x = Math.round(X(tk) - 0.5);
        rect(c, x, edge, x + 1, edge + S.tick_len + 2, C.grey);
      }
      for (const ti of run.impacts) {
        if (ti < t0 || ti > t1 || ti > T_END) continue;
        const x = Math.round(X(ti) - 0.5);
        rect(c, x, 0, x + 1, edge, C.impact);
        rect(c, x, edge - FS.IMPACT_TICK * u, x + 1, edge, C.grey);
      }
      const order = P.names.filter(function (n) { return n !== "E"; }).concat(["E"]);
      for (const name of order) {
        const band = run.bands[name];
        if (!band) continue;
        c.fillStyle = C.bands[name] || C.grey;
        for (let col = Math.max(0, c0 - 1); col < Math.min(S.tape_w, c1 + 1); col++) {
          const a = band[0][col], b = band[1][col];
          if (a === a) c.fillRect(col - c0, Math.round(a - S.tape_y), 1, Math.max(1, Math.round(b) - Math.round(a) + 1));
        }
      }
      const i0 = Math.max(0, atOrAfter(run, t0) - 1), i1 = Math.min(run.n, atOrAfter(run, t1) + 2);
      c.lineWidth = Math.max(1, Math.round(FS.LINE * u)); c.lineJoin = "round";
      for (const name of order) {
        if (run.bands[name]) continue;
        const v = run.E[name];
        c.beginPath(); let open = false;
        for (let i = i0; i < i1; i++) {
          const y = stripY(v[i]) - S.tape_y;
          if (!isFinite(y)) { open = false; continue; }
          if (open) c.lineTo(X(run.t[i]), y); else { c.moveTo(X(run.t[i]), y); open = true; }
        }
        c.strokeStyle = C.terms[name] || C.grey; c.stroke();
      }
      const bar = Math.max(1, Math.round(FS.CONTACT_BAR * u));
      for (const [body, a, b] of run.contacts) {
        const y = edge - (body === "B" ? 1 : 2) * bar;
        rect(c, X(a), y, X(Math.min(b, T_END)) + 1, y + bar, C.terms[body]);
      }
    }
    function piece(run, c0) {
      let p = run.pieces.get(c0);
      if (!p) {
        const S = P.strip, c1 = Math.min(S.tape_w, c0 + FS.TAPE_CHUNK);
        p = document.createElement("canvas");
        p.width = Math.max(1, Math.round(c1 * scale) - Math.round(c0 * scale));
        p.height = Math.max(1, Math.ceil(S.tape_h * scale));
        const c = p.getContext("2d");
        c.setTransform(scale, 0, 0, scale, 0, 0);
        drawTape(c, run, c0, c1);
        if (run.pieces.size > 6) run.pieces.clear();
        run.pieces.set(c0, p);
      }
      return p;
    }
    // The strip at run's sample j: its window of the tape (copied in device pixels), what lies
    // after the cursor faded, the cursor, and the time labels under it.
    function drawStrip(c, run, j, panel) {
      const S = P.strip, [sx0, , , sy1] = S.box, pps = S.px_per_s, t = run.t[j];
      const x = Math.round(t * pps), left = Math.min(Math.max(0, x - S.cursor_px), S.tape_w - S.inner_w);
      const right = left + S.inner_w, chunk = FS.TAPE_CHUNK;
      const ox = panel.at[0] - panel.src[0], oy = panel.at[1] - panel.src[1];
      c.save(); c.setTransform(1, 0, 0, 1, 0, 0);
      for (let c0 = Math.floor(left / chunk) * chunk; c0 < right; c0 += chunk) {
        const p = piece(run, c0), a = Math.max(left, c0), b = Math.min(right, c0 + chunk);
        const sx = Math.round(a * scale) - Math.round(c0 * scale), sw = Math.round(b * scale) - Math.round(a * scale);
        const dx = Math.round((S.inner_x + a - left + ox) * scale);
        if (sw > 0) c.drawImage(p, sx, 0, sw, p.height, dx, Math.round((S.tape_y + oy) * scale), sw, p.height);
      }
      c.restore();
      const xc = S.inner_x + x - left;
      c.globalAlpha = 1 - FS.FUTURE;
      rect(c, xc + 1, S.tape_y, S.inner_x + S.inner_w, sy1, C.white);
      c.globalAlpha = 1;
      const cw = Math.max(1, Math.round(FS.CURSOR * u));
      rect(c, xc - cw / 2 + 0.5, S.tape_y, xc + cw / 2 + 0.5, sy1, C.ink);
      const xMin = sx0 - Math.round(FS.LABEL_OVERHANG * u), t0 = left / pps, t1 = (right - 1) / pps;
      c.font = fSmallNote;
      for (const [tk, label] of S.time_ticks) {
        if (tk < t0 - 1e-9 || tk > t1 + 1e-9) continue;
        const xt = S.inner_x + tk * pps - left, half = c.measureText(label).width / 2;
        if (xt - half >= xMin && xt + half <= W - FS.LABEL_EDGE * u) text(c, label, xt + 0.5, sy1 + FS.LABEL_GAP * u, "mt", fSmallNote, C.grey);
      }
    }

    // --- a frame -------------------------------------------------------------------------------
    function impactSince(run, j) {
      const t = run.t[j];
      for (const ti of run.impacts) if (ti > t - 1 / FPS && ti <= t) return true;
      return false;
    }
    // Where a run's dumbbell at sample j may draw (the GIF's crop around it), frame px.
    function dumbbellBox(run, j, impact) {
      const ax = run.A[2 * j], ay = run.A[2 * j + 1], bx = run.B[2 * j], by = run.B[2 * j + 1];
      if (!(isFinite(ax) && isFinite(ay) && isFinite(bx) && isFinite(by))) return null;
      const wd = P.world, pa = px(ax, ay), pb = px(bx, by), twoD = wd.dimensions === 2;
      const m = Math.max(wd.radius_px[0], wd.radius_px[1], wd.amp) + (twoD ? FW.CROP_2D : FW.CROP_1D) * u;
      const mx = m + (twoD ? FW.LABELS_2D * u : 0);
      let x0 = Math.min(pa[0], pb[0]) - mx, x1 = Math.max(pa[0], pb[0]) + mx + FW.LABELS_RIGHT * u;
      const y0 = Math.min(pa[1], pb[1]) - mx;
      let y1 = Math.max(pa[1], pb[1]) + (twoD ? mx : m);
      if (impact && wd.floor_y !== null) {
        const low = pa[1] > pb[1] ? pa : pb;
        x0 = Math.min(x0, low[0] - FW.IMPACT_CROP * u); x1 = Math.max(x1, low[0] + FW.IMPACT_CROP * u);
        y1 = Math.max(y1, wd.floor_y + FW.IMPACT_WORD * u);
      }
      return [Math.max(0, x0), Math.max(0, y0), Math.min(L.scene_w, x1), Math.min(H, y1)];
    }
    // What changes from frame to frame besides the dumbbells: put back from the background.
    const FIXED = (function () {
      const B = P.bars, S = P.strip, out = [];
      const twoD = P.world.dimensions === 2;
      out.push([FW.TIME_BOX[0] * u, FW.TIME_BOX[1] * u, L.scene_w - FW.TIME_BOX[0] * u, (twoD ? FW.TIME_BOTTOM_2D : FW.TIME_BOTTOM_1D) * u]);
      const top = B.rows[0][1] - 4 - Math.max(3, Math.round(FB.MARKER * u)), bottom = B.rows[B.rows.length - 1][2] + 4;
      out.push([B.left - 2, top, W, bottom]);
      const below = B.rows[B.rows.length - 1][2];
      const limit = S ? S.box[1] - Math.round(FB.MOMENTUM_GAP * u) : H - Math.round(FB.MOMENTUM_EDGE * u);
      out.push([B.box[0], (below + limit) / 2 - FB.MOMENTUM_HALF * u - 1, W, (below + limit) / 2 + FB.MOMENTUM_HALF * u + 1]);
      if (S) out.push([S.box[0] - Math.round(FS.LABEL_OVERHANG * u) - 1, S.box[3] + S.tick_len + 1, W, H]);
      return out;
    })();
    function frame(c, p) {
      const sel = runs[state.run], j = nearest(sel, state.t), impact = j > 0 && impactSince(sel, j);
      c.save(); c.beginPath(); c.rect(0, 0, L.scene_w, H); c.clip();  // the scene panel's
      for (let k = 0; k < runs.length; k++) {
        if (k !== state.run) drawDumbbell(c, runs[k], nearest(runs[k], state.t), true, false);
      }
      drawDumbbell(c, sel, j, false, impact);
      drawTime(c, sel, j);
      c.restore();
      drawBars(c, sel, j);
      if (P.strip) drawStrip(c, sel, j, p);
    }
    function boxes() {
      const sel = runs[state.run], j = nearest(sel, state.t), impact = j > 0 && impactSince(sel, j);
      return runs.map(function (run, k) {
        return k === state.run ? dumbbellBox(sel, j, impact) : dumbbellBox(run, nearest(run, state.t), false);
      }).concat(FIXED);
    }
    function rows() {
      const out = [];
      for (const name of P.names) out.push([name, name + " (" + DOC.units.energy + ")", C.terms[name] || C.grey]);
      if (runs.some(function (r) { return r.L; })) out.push(["L_cm", "L_cm (" + DOC.units.L_cm + ")", null]);
      return out;
    }
    return { drawStatic: drawStatic, frame: frame, boxes: boxes, rows: rows, reset: function () { for (const run of runs) run.pieces = new Map(); } };
  }

  // --- what a recorded space's frame shows (the painter of animation/recording.py) -------------
  function spaceDrawer() {
    const X = P.factors, SS = X.SS, LW = Math.max(1, Math.round(1.5 * u * SS)) / SS;
    const run = runs[0], n = run.n;
    const poses = decode(P.poses), offsets = [0];
    for (const c of P.counts) offsets.push(offsets[offsets.length - 1] + 3 * c);
    const sets = P.shapes.map(function (g) { return Object.assign({}, g, { local: decode(g.local) }); });
    for (const g of sets) {
      g.start = [0];
      for (const k of g.npts) g.start.push(g.start[g.start.length - 1] + 2 * k);
    }
    const inks = P.shape_colours, grey = inks[inks.length - 1];
    function colourOf(ink) { return ink >= 0 ? inks[ink % (inks.length - 1)] : grey; }
    const oneView = P.views.length === 1, oneStatic = P.statics.length <= 1;
    function view(k) { return P.views[P.view_of[k]]; }
    function toPx(v, x, y) { return [v[1] + x * v[0], v[2] + v[3] * y * v[0]]; }
    const fTime = font(Math.max(9, Math.round(14 * u)), true), fText = font(Math.max(8, Math.round(12 * u)));
    const fSmall = font(Math.round(10 * u));
    function circle(c, v, x, y, r, angle, colours) {
      const p = toPx(v, x, y), R = Math.max(r * v[0], 1.5 * u);
      if (!(isFinite(p[0]) && isFinite(p[1]) && isFinite(R))) return;
      c.beginPath(); c.arc(p[0], p[1], Math.max(0.1, R - LW / 2), 0, 2 * Math.PI);
      c.fillStyle = colours[1]; c.fill(); c.strokeStyle = colours[0]; c.lineWidth = LW; c.stroke();
      if (isFinite(angle)) line(c, [p, [p[0] + R * Math.cos(angle), p[1] + v[3] * R * Math.sin(angle)]], colours[0], LW);
    }
    function segment(c, v, ax, ay, bx, by, r, colours) {
      const a = toPx(v, ax, ay), b = toPx(v, bx, by), w = Math.max(LW, 2 * r * v[0]);
      if (![a[0], a[1], b[0], b[1], w].every(isFinite)) return;
      c.lineCap = "round";
      line(c, [a, b], colours[0], w);
      if (w > 2 * LW) line(c, [a, b], colours[1], w - 2 * LW);
      c.lineCap = "butt";
    }
    function polygon(c, v, flat, colours) {
      if (flat.length < 4) return;
      c.beginPath();
      for (let i = 0; i < flat.length; i += 2) {
        const p = toPx(v, flat[i], flat[i + 1]);
        if (i) c.lineTo(p[0], p[1]); else c.moveTo(p[0], p[1]);
      }
      c.closePath(); c.fillStyle = colours[1]; c.fill(); c.strokeStyle = colours[0]; c.lineWidth = LW; c.stroke();
    }
    function zigzag(a, b) {
      const dx = b[0] - a[0], dy = b[1] - a[1], length = Math.hypot(dx, dy);
      const amp = Math.min(X.SPRING_WIDTH * u, 0.1 * length), pts = [a, [a[0] + dx * X.LEAD, a[1] + dy * X.LEAD]];
      if (!(length > 0)) return [a, b];
      const nx = -dy / length * amp, ny = dx / length * amp;
      for (let i = 0; i < 2 * X.COILS; i++) {
        const f = X.LEAD + (1 - 2 * X.LEAD) * (i + 0.5) / (2 * X.COILS), side = i % 2 === 0 ? 1 : -1;
        pts.push([a[0] + dx * f + side * nx, a[1] + dy * f + side * ny]);
      }
      pts.push([a[0] + dx * (1 - X.LEAD), a[1] + dy * (1 - X.LEAD)], b);
      return pts;
    }
    function item(c, v, it) {
      const kind = it[0];
      if (kind === "circle") circle(c, v, it[3], it[4], it[5], it[6] === null ? NaN : it[6], colourOf(it[1]));
      else if (kind === "seg") segment(c, v, it[3], it[4], it[5], it[6], it[7], colourOf(it[1]));
      else if (kind === "poly") polygon(c, v, it[3], colourOf(it[1]));
      else if (kind === "spring" || kind === "line") {
        const a = toPx(v, it[3], it[4]), b = toPx(v, it[5], it[6]);
        if ([a[0], a[1], b[0], b[1]].every(isFinite)) line(c, kind === "spring" ? zigzag(a, b) : [a, b], P.spring, LW);
      } else if (kind === "dot") {
        const p = toPx(v, it[3], it[4]);
        if (isFinite(p[0]) && isFinite(p[1])) { c.beginPath(); c.arc(p[0], p[1], 3 * u, 0, 2 * Math.PI); c.fillStyle = P.ink; c.fill(); }
      } else if (kind === "rotary" && it[5] !== null) {
        const p = toPx(v, it[3], it[4]), pts = [];
        for (let i = 0; i <= 60; i++) {
          const f = i / 60, a = f * 2.5 * 2 * Math.PI + it[5], rr = (4 + 8 * f) * u;
          pts.push([p[0] + rr * Math.cos(a), p[1] + v[3] * rr * Math.sin(a)]);
        }
        line(c, pts, P.spring, LW);
      }
    }
    function statics(c, k) { for (const it of P.statics[P.static_of[k]] || []) item(c, view(k), it); }
    // Many circles (as many as the GIF draws flat): each disc pasted from a picture of it
    // drawn once per colour and size (in device pixels), the radius lines one path per colour.
    const sprites = new Map();
    function sprite(ink, R) {
      const key = ink * 1e7 + Math.round(2 * R);
      let sp = sprites.get(key);
      if (!sp) {
        const colours = colourOf(ink), half = Math.ceil((R + LW) * scale) + 1;
        sp = document.createElement("canvas"); sp.width = sp.height = 2 * half;
        const g = sp.getContext("2d");
        g.setTransform(scale, 0, 0, scale, half, half);
        g.beginPath(); g.arc(0, 0, Math.max(0.1, R - LW / 2), 0, 2 * Math.PI);
        g.fillStyle = colours[1]; g.fill(); g.strokeStyle = colours[0]; g.lineWidth = LW; g.stroke();
        sp.half = half;
        if (sprites.size > 256) sprites.clear();
        sprites.set(key, sp);
      }
      return sp;
    }
    function manyCircles(c, g, v, base) {
      const lines = {}, m = c.getTransform();
      c.save(); c.setTransform(1, 0, 0, 1, 0, 0);
      for (let j = 0; j < g.kind.length; j++) {
        if (g.kind[j] !== "circle") continue;
        const o = base + 3 * g.body[j], a = poses[o + 2], s0 = g.start[j];
        const lx = g.local[s0], ly = g.local[s0 + 1], cos = Math.cos(a), sin = Math.sin(a);
        const p = toPx(v, poses[o] + cos * lx - sin * ly, poses[o + 1] + sin * lx + cos * ly);
        const R = Math.round(2 * Math.max(g.r[j] * v[0], 1.5 * u)) / 2;
        if (!(isFinite(p[0]) && isFinite(p[1]) && isFinite(R))) continue;
        const sp = sprite(g.ink[j], R);
        c.drawImage(sp, Math.round(m.a * p[0] + m.e) - sp.half, Math.round(m.d * p[1] + m.f) - sp.half);
        if (isFinite(a)) {
          const l = lines[g.ink[j]] || (lines[g.ink[j]] = new Path2D());
          l.moveTo(p[0], p[1]); l.lineTo(p[0] + R * Math.cos(a), p[1] + v[3] * R * Math.sin(a));
        }
      }
      c.restore();
      c.lineWidth = LW;
      for (const key in lines) { c.strokeStyle = colourOf(Number(key))[0]; c.stroke(lines[key]); }
    }
    function moving(c, k) {
      const g = sets[P.shape_of[k]], v = view(k), base = offsets[k], pts = [];
      const many = g.kind.length >= P.factors.FLAT_MANY;
      if (many) manyCircles(c, g, v, base);
      for (let j = 0; j < g.kind.length; j++) {
        if (many && g.kind[j] === "circle") continue;
        const o = base + 3 * g.body[j], x = poses[o], y = poses[o + 1], a = poses[o + 2];
        const cos = Math.cos(a), sin = Math.sin(a), s0 = g.start[j], m = g.npts[j];
        const colours = colourOf(g.ink[j]);
        pts.length = 0;
        for (let i = 0; i < m; i++) {
          const lx = g.local[s0 + 2 * i], ly = g.local[s0 + 2 * i + 1];
          pts.push(x + cos * lx - sin * ly, y + sin * lx + cos * ly);
        }
        if (g.kind[j] === "circle") circle(c, v, pts[0], pts[1], g.r[j], a, colours);
        else if (g.kind[j] === "seg") segment(c, v, pts[0], pts[1], pts[2], pts[3], g.r[j], colours);
        else polygon(c, v, pts, colours);
      }
      for (const it of P.extras[k]) item(c, v, it);
    }
    const B = P.bars, S = P.strip;
    function barX(value) { return B.zero + value * B.px_per_j; }
    function stripX(t) { return S.box[0] + 1 + (S.box[2] - S.box[0] - 2) * (t - S.t0) / S.span; }
    function stripY(value) {
      const [, sy0, , sy1] = S.box;
      return sy1 - S.pad - (sy1 - sy0 - 2 * S.pad) * (value - B.scale.lo) / (B.scale.hi - B.scale.lo);
    }
    function drawStatic(c) {
      rect(c, 0, 0, W, H, P.white);
      if (oneView && oneStatic) { c.save(); c.beginPath(); c.rect(0, 0, SCENE_W, H); c.clip(); statics(c, 0); c.restore(); }
      if (P.title) text(c, P.title, SCENE_W - 8 * u, 6 * u, "rt", font(Math.round(12 * u), true), P.ink);
      if (!B) return;
      line(c, [[SCENE_W, 8 * u], [SCENE_W, H - 8 * u]], P.light, 1);
      const [bx0, by0] = B.box;
      text(c, B.title, bx0, by0, "lt", font(Math.round(13 * u), true), P.ink);
      const sw = Math.round(9 * u);
      for (const [name, top, bot] of B.rows) {
        const mid = (top + bot) / 2;
        rect(c, bx0, mid - sw / 2, bx0 + sw, mid + sw / 2, B.inks[name]);
        text(c, B.labels[name], bx0 + sw + 5 * u, mid, "lm", font(Math.round(12 * u)), P.ink);
      }
      line(c, [[B.zero + 0.5, B.rows[0][1] - 3], [B.zero + 0.5, B.rows[B.rows.length - 1][2] + 3]], P.grey, 1);
      if (!S) return;
      const [sx0, sy0, sx1, sy1] = S.box;
      c.strokeStyle = P.light; c.lineWidth = 1; c.strokeRect(sx0 + 0.5, sy0 + 0.5, sx1 - sx0, sy1 - sy0);
      for (const [value, label] of S.ticks) {
        const y = stripY(value);
        line(c, [[sx0 + 1, y], [sx1 - 1, y]], P.grid, 1);
        text(c, label, sx0 - 4 * u, y, "rm", fSmall, P.grey);
      }
      if (S.axis) text(c, S.axis, sx0, sy0 - 4 * u, "ls", fSmall, P.grey);  // unit, power of ten
      for (const [tk, label] of S.time_ticks) {
        const x = stripX(tk);
        line(c, [[x, sy1], [x, sy1 + 3 * u]], P.grey, 1);
        text(c, label, x, sy1 + 5 * u, "mt", fSmall, P.grey);
      }
      text(c, "t (" + P.time_unit + ")", sx0 - 4 * u, sy1 + 5 * u, "rt", fSmall, P.grey);
      const order = B.rows.map(function (r) { return r[0]; }).filter(function (name) { return name !== "E"; });
      const series = order.map(function (name) { return [B.inks[name], run.E[name]]; });
      if (B.heat) series.push([B.heat_ink, Float64Array.from(run.E.E, function (e, i) { return e + run.E.heat[i]; })]);
      if (run.E.E) series.push([B.inks.E, run.E.E]);
      c.lineJoin = "round";
      for (const [colour, values] of series) {
        c.beginPath(); let open = false;
        for (let i = 0; i < n; i++) {
          const y = stripY(values[i]);
          if (!isFinite(y)) { open = false; continue; }
          if (open) c.lineTo(stripX(run.t[i]), y); else { c.moveTo(stripX(run.t[i]), y); open = true; }
        }
        c.strokeStyle = colour; c.lineWidth = LW; c.stroke();
      }
    }
    function frame(c) {
      const k = nearest(run, state.t);
      c.save(); c.beginPath(); c.rect(0, 0, SCENE_W, H); c.clip();
      if (!(oneView && oneStatic)) statics(c, k);
      moving(c, k);
      c.restore();
      text(c, "t = " + run.t[k].toFixed(T_DECIMALS) + " " + P.time_unit, 6 * u, 6 * u, "lt", fTime, P.ink);
      if (!B) return;
      for (const [name, top, bot] of B.rows) {
        const value = run.E[name][k];
        if (isFinite(value)) {
          const a = Math.round(barX(0)), b = Math.round(barX(value)), lo = Math.min(a, b), hi = Math.max(a, b);
          if (name === "E" && B.heat && run.E.heat[k] > 0) {
            const h = Math.max(hi, Math.round(barX(value + run.E.heat[k])));
            if (h > hi) rect(c, hi, top, h, bot, B.heat_ink);
          }
          if (hi > lo) rect(c, lo, top, hi, bot, B.inks[name]);
        }
        text(c, energyText(value), B.box[2], (top + bot) / 2, "rm", fText, P.ink);
      }
      if (!S) return;
      const [, sy0, sx1, sy1] = S.box, x = Math.round(stripX(run.t[k]));
      // What has not happened yet: faded.
      c.globalAlpha = 1 - X.FUTURE;
      rect(c, x + 1, sy0 + 1, sx1, sy1, P.white);
      c.globalAlpha = 1;
      const w = Math.max(1, Math.round(1.2 * u));
      rect(c, x - w / 2 + 0.5, sy0 + 1, x + w / 2 + 0.5, sy1, P.ink);
    }
    function boxes() {
      if (!(oneView && oneStatic)) return null;
      const out = [[0, 0, SCENE_W, H]];
      if (B) out.push([B.left - 1, B.rows[0][1] - 3, W, B.rows[B.rows.length - 1][2] + 3]);
      if (S) out.push([S.box[0] + 1, S.box[1] + 1, S.box[2], S.box[3]]);
      return out;
    }
    function rows() {
      return B ? B.rows.map(function (r) { return [r[0], B.labels[r[0]] + " (" + DOC.units.energy + ")", B.inks[r[0]]]; }) : [];
    }
    return { drawStatic: drawStatic, frame: frame, boxes: boxes, rows: rows, reset: function () { sprites.clear(); } };
  }

  const drawer = SPACE ? spaceDrawer() : sceneDrawer();

  let drawn = null;  // what the last frame drew where it changes (boxes to put back), or null
  function restore(box) {
    for (const p of panels()) {
      const x0 = Math.max(box[0], p.src[0]), y0 = Math.max(box[1], p.src[1]);
      const x1 = Math.min(box[2], p.src[2]), y1 = Math.min(box[3], p.src[3]);
      if (!(x1 > x0 && y1 > y0)) continue;
      const dx0 = Math.floor((x0 - p.src[0] + p.at[0]) * scale), dy0 = Math.floor((y0 - p.src[1] + p.at[1]) * scale);
      const dx1 = Math.ceil((x1 - p.src[0] + p.at[0]) * scale), dy1 = Math.ceil((y1 - p.src[1] + p.at[1]) * scale);
      ctx.drawImage(background, dx0, dy0, dx1 - dx0, dy1 - dy0, dx0, dy0, dx1 - dx0, dy1 - dy0);
    }
  }
  let shownKey = null;  // the samples the canvas shows: a frame that shows the same is not drawn again
  function render(force) {
    const key = state.run + ":" + runs.map(function (r) { return nearest(r, state.t); }).join(",");
    if (!force && key === shownKey && drawn !== null) { showValues(!state.playing); return; }
    shownKey = key;
    const t0 = performance.now();
    const boxes = drawer.boxes();
    ctx.setTransform(1, 0, 0, 1, 0, 0);
    if (drawn === null || boxes === null || force) ctx.drawImage(background, 0, 0);
    else for (const box of drawn.concat(boxes)) if (box) restore(box);
    drawn = boxes;
    for (const p of panels()) {
      ctx.setTransform(scale, 0, 0, scale, 0, 0);
      ctx.save();
      ctx.beginPath(); ctx.rect(p.at[0], p.at[1], p.src[2] - p.src[0], p.src[3] - p.src[1]); ctx.clip();
      ctx.translate(p.at[0] - p.src[0], p.at[1] - p.src[1]);
      drawer.frame(ctx, p);
      ctx.restore();
    }
    const ms = performance.now() - t0;
    stats.frames += 1; stats.drawMs.push(ms);
    if (stats.drawMs.length > 2000) stats.drawMs.shift();
    showValues(!state.playing);
  }

  function resize() {
    const stage = document.getElementById("stage");
    stacked = stage.clientWidth < STACK_BELOW;
    const [lw, lh] = logicalSize();
    // As large as the window allows, the controls beside it (a wide window) or under it.
    const side = document.getElementById("side"), beside = side.offsetLeft > stage.offsetLeft + 10;
    const reserved = stage.getBoundingClientRect().top + window.scrollY + (beside ? 16 : side.offsetHeight + 16);
    const room = Math.max(240, window.innerHeight - reserved) * lw / lh;
    const cssW = Math.max(120, Math.min(stage.clientWidth, stacked ? Infinity : room));
    const dpr = window.devicePixelRatio || 1, cssH = cssW * lh / lw;
    canvas.style.width = cssW + "px"; canvas.style.height = cssH + "px";
    canvas.width = Math.max(1, Math.round(cssW * dpr)); canvas.height = Math.max(1, Math.round(cssH * dpr));
    scale = canvas.width / lw;
    background = document.createElement("canvas");
    background.width = canvas.width; background.height = canvas.height;
    const b = background.getContext("2d");
    rect(b, 0, 0, canvas.width, canvas.height, "#ffffff");
    for (const p of panels()) {
      b.setTransform(scale, 0, 0, scale, 0, 0);
      b.save(); b.beginPath(); b.rect(p.at[0], p.at[1], p.src[2] - p.src[0], p.src[3] - p.src[1]); b.clip();
      b.translate(p.at[0] - p.src[0], p.at[1] - p.src[1]);
      drawer.drawStatic(b);
      b.restore();
    }
    drawer.reset();
    drawn = null;
    render(true);
  }

  // --- the controls and the table of values ----------------------------------------------------
  const $ = function (id) { return document.getElementById(id); };
  const slider = $("time"), timeText = $("time-text"), playButton = $("play");
  slider.min = "0"; slider.max = String(T_END); slider.step = String(SPACING);
  $("title").textContent = P.title;
  const notes = [];
  if (runs.length > 1) notes.push("Runs on one clock: the chosen one drawn solid, its bars shown; the others as ghosts.");
  for (const run of runs) if (run.note) notes.push(run.label + ": " + run.note);
  $("notes").textContent = notes.join(" ");
  const runSelect = $("run");
  runs.forEach(function (run, k) {
    const o = document.createElement("option"); o.value = String(k); o.textContent = run.label || ("run " + (k + 1));
    runSelect.appendChild(o);
  });
  if (runs.length > 1) {
    $("run-label").hidden = false;
    $("stage").appendChild($("readout"));  // a column per run: under the picture, wider
  }
  const cells = [];
  (function table() {
    const head = $("readout-head"), body = $("readout-body");
    runs.forEach(function (run, k) {
      const th = document.createElement("th"); th.scope = "col"; th.textContent = run.label || "value"; th.title = run.label;
      th.dataset.run = String(k); head.appendChild(th);
    });
    const rows = [["t", "t (" + DOC.units.time + ")", null]].concat(drawer.rows());
    for (const [key, label, colour] of rows) {
      const tr = document.createElement("tr"), th = document.createElement("th");
      th.scope = "row";
      if (colour) { const s = document.createElement("span"); s.className = "swatch"; s.style.background = colour; th.appendChild(s); }
      th.appendChild(document.createTextNode(label)); tr.appendChild(th);
      runs.forEach(function (run, k) {
        const td = document.createElement("td"); td.dataset.run = String(k); td.dataset.name = key;
        tr.appendChild(td); cells.push([td, k, key]);
      });
      body.appendChild(tr);
    }
  })();
  let valuesAt = -Infinity;
  // The time and the table: at once when paused, about ten times a second while playing.
  function showValues(now) {
    const clock = performance.now();
    if (!now && clock - valuesAt < 100) return;
    valuesAt = clock;
    const sel = runs[state.run], j = nearest(sel, state.t);
    timeText.textContent = "t = " + sel.t[j].toFixed(T_DECIMALS) + " " + DOC.units.time;
    slider.value = String(state.t);
    for (const [td, k, key] of cells) {
      const run = runs[k], i = nearest(run, state.t);
      const text = key === "t" ? run.t[i].toFixed(T_DECIMALS) : key === "L_cm" ? (run.L ? fixed(run.L[i], 4, "+") : "") : energyText(run.E[key][i]);
      if (td.textContent !== text) td.textContent = text;
    }
    document.body.dataset.shown = sel.t[j].toFixed(T_DECIMALS);
  }
  function seek(t) { state.t = Math.min(Math.max(0, t), T_END); state.last = null; render(); }
  function frameStep(dir, sample) {
    if (sample) {
      const run = runs[state.run], j = Math.min(Math.max(0, nearest(run, state.t) + dir), run.n - 1);
      seek(run.t[j]); return;
    }
    const k = dir > 0 ? Math.floor(state.t * FPS + 1e-9) + 1 : Math.ceil(state.t * FPS - 1e-9) - 1;
    seek(Math.min(Math.max(0, k / FPS), T_END));
  }
  function jumpImpact(dir) {
    const run = runs[state.run], j = nearest(run, state.t);
    let best = null;
    for (const ti of run.impacts) {
      const at = atOrAfter(run, ti);
      if (dir > 0 && at > j && (best === null || at < best)) best = at;
      if (dir < 0 && at < j && (best === null || at > best)) best = at;
    }
    if (best !== null) { pause(); seek(run.t[best]); }
  }
  function play() {
    if (state.playing) return;
    if (state.t >= T_END - 1e-12) state.t = 0;
    state.playing = true; state.last = null; playButton.textContent = "Pause";
    playButton.setAttribute("aria-pressed", "true");
    requestAnimationFrame(tick);
  }
  function pause() {
    const was = state.playing;
    state.playing = false; playButton.textContent = "Play"; playButton.setAttribute("aria-pressed", "false");
    if (was) showValues(true);
  }
  function toggle() { if (state.playing) pause(); else play(); }
  function tick(now) {
    if (!state.playing) return;
    if (state.last !== null) {
      let t = state.t + (now - state.last) / 1000 * state.speed;
      if (t > T_END) { if (state.loop) t = t % Math.max(T_END, 1e-9); else { t = T_END; pause(); } }
      state.t = t;
    }
    state.last = now; stats.playedFrames += 1;
    render();
    if (state.playing) requestAnimationFrame(tick);
  }
  playButton.addEventListener("click", toggle);
  $("back").addEventListener("click", function () { pause(); frameStep(-1, false); });
  $("forward").addEventListener("click", function () { pause(); frameStep(1, false); });
  $("prev-impact").addEventListener("click", function () { jumpImpact(-1); });
  $("next-impact").addEventListener("click", function () { jumpImpact(1); });
  // A run without impacts (a recorded space, a run that ends before the first) has nothing
  // to jump to: its impact buttons are disabled, and say why.
  function impactButtons() {
    const none = runs[state.run].impacts.length === 0;
    for (const id of ["prev-impact", "next-impact"]) {
      const b = $(id);
      if (b.dataset.title === undefined) b.dataset.title = b.title;
      b.disabled = none;
      b.title = none ? "No impacts in this run" : b.dataset.title;
    }
  }
  impactButtons();
  slider.addEventListener("input", function () { seek(parseFloat(slider.value)); });
  $("speed").addEventListener("change", function (e) { state.speed = parseFloat(e.target.value); });
  $("loop").addEventListener("change", function (e) { state.loop = e.target.checked; });
  runSelect.addEventListener("change", function (e) { state.run = parseInt(e.target.value, 10); impactButtons(); render(true); });
  document.addEventListener("keydown", function (e) {
    if (e.altKey || e.ctrlKey || e.metaKey) return;
    const tag = e.target && e.target.tagName;
    if (tag === "SELECT" && e.key !== " ") return;
    switch (e.key) {
      case " ": case "Spacebar": e.preventDefault(); if (!e.repeat) toggle(); break;
      case "ArrowLeft": e.preventDefault(); pause(); frameStep(-1, e.shiftKey); break;
      case "ArrowRight": e.preventDefault(); pause(); frameStep(1, e.shiftKey); break;
      case "[": jumpImpact(-1); break;
      case "]": jumpImpact(1); break;
      case "Home": e.preventDefault(); pause(); seek(0); break;
      case "End": e.preventDefault(); pause(); seek(T_END); break;
      default: return;
    }
  });
  // A button or a box with the focus would act on the space bar's release as well.
  document.addEventListener("keyup", function (e) { if (e.key === " " || e.key === "Spacebar") e.preventDefault(); });

  // --- for scripts and tests: the state, a seek, and the drawing's speed -----------------------
  window.dumbbellPlayer = {
    seek: function (t) { pause(); seek(Number(t)); return runs[state.run].t[nearest(runs[state.run], state.t)]; },
    state: function () {
      return { t: state.t, playing: state.playing, speed: state.speed, loop: state.loop, run: state.run,
        shown: runs.map(function (r) { return r.t[nearest(r, state.t)]; }) };
    },
    stats: function () {
      const d = stats.drawMs.slice().sort(function (a, b) { return a - b; });
      const mean = d.reduce(function (a, b) { return a + b; }, 0) / Math.max(1, d.length);
      return { frames: stats.frames, played: stats.playedFrames, meanDrawMs: mean,
        p95DrawMs: d.length ? d[Math.min(d.length - 1, Math.floor(0.95 * d.length))] : 0 };
    },
    // Plays for `seconds` of wall time from the start and measures, in the page, the frames
    // drawn per second (requestAnimationFrame) and the time each drawing took.
    measure: function (seconds) {
      return new Promise(function (resolve) {
        pause(); seek(0); stats.drawMs = [];
        let n = 0, first = null, drawnBefore = stats.frames;
        state.playing = true; state.last = null; state.loop = true;
        function step(now) {
          if (first === null) first = now;
          if (state.last !== null) state.t = (state.t + (now - state.last) / 1000 * state.speed) % Math.max(T_END, 1e-9);
          state.last = now; render(); n += 1;
          if (now - first < seconds * 1000) { requestAnimationFrame(step); return; }
          state.playing = false; showValues(true);
          const d = stats.drawMs.slice().sort(function (a, b) { return a - b; });
          resolve({ frames: n, seconds: (now - first) / 1000, fps: (n - 1) / ((now - first) / 1000),
            drawn: stats.frames - drawnBefore, drawnPerSecond: (stats.frames - drawnBefore) / ((now - first) / 1000),
            meanDrawMs: d.reduce(function (a, b) { return a + b; }, 0) / d.length,
            p95DrawMs: d[Math.min(d.length - 1, Math.floor(0.95 * d.length))] });
        }
        requestAnimationFrame(step);
      });
    },
  };
  let stageWidth = null;
  if (window.ResizeObserver) new ResizeObserver(function () {
    const w = document.getElementById("stage").clientWidth;
    if (w !== stageWidth) { stageWidth = w; resize(); }
  }).observe(document.getElementById("stage"));
  window.addEventListener("resize", resize);
  const hash = /[#&]t=([0-9.eE+-]+)/.exec(window.location.hash);
  if (hash && isFinite(parseFloat(hash[1]))) state.t = Math.min(Math.max(0, parseFloat(hash[1])), T_END);
  resize();
  document.body.dataset.ready = "1";
})();
