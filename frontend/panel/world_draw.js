// A world (docs/model.md §8, docs/worlds.md) drawn in an SVG: each side's segments coloured by
// their friction mu, footholds (segments with grip that lean) ticked along their normal into the
// chute by their inclination beta, axes in the document's units. The World tab's editor and
// History's thumbnails draw with it. Every value reaches the page as SVG attributes or text.
const SVG = "http://www.w3.org/2000/svg";
export const SIDES = ["left", "right"];
export const MU_TOP = 3;  // the colour scale's top: mu at or above it takes its darkest colour
// A sequential scale, light (little grip) to dark (much): viridis, reversed.
const STOPS = [[0, [253, 231, 37]], [0.25, [94, 201, 98]], [0.5, [33, 145, 140]], [0.75, [59, 82, 139]], [1, [68, 1, 84]]];
export const MODEL_MU_COLOR = "#9a9a9a";
export const NO_SLIP_COLOR = "#111111";
export const FACES_UP = "#1f77b4", FACES_DOWN = "#d9532b";
const EDITOR = { height: 640, top: 16, bottom: 40, axis: 44, margin: 136 };

// An SVG element with these attributes (each set as a string) and ``text`` as its text.
export function svgElement(tag, attributes = {}, text) {
  const node = document.createElementNS(SVG, tag);
  for (const [name, value] of Object.entries(attributes)) node.setAttribute(name, String(value));
  if (text !== undefined) node.textContent = text;
  return node;
}

const isPoint = (p) => Array.isArray(p) && p.length === 2 && p.every((v) => typeof v === "number" && Number.isFinite(v));

// A mu entry in words: a number, null (the model's mu) or "inf" (no slip).
export function muWords(entry) {
  if (entry === null || entry === undefined) return "the model's mu";
  if (entry === "inf") return "inf (no slip)";
  return entry === 0 ? "0 (no grip)" : String(entry);
}

export function muColor(entry) {
  if (entry === null || entry === undefined) return MODEL_MU_COLOR;
  if (entry === "inf") return NO_SLIP_COLOR;
  const at = Math.min(Math.max(Number(entry) / MU_TOP, 0), 1);
  const upper = STOPS.findIndex(([stop]) => stop >= at);
  if (upper <= 0) return rgb(STOPS[0][1]);
  const [s0, c0] = STOPS[upper - 1], [s1, c1] = STOPS[upper];
  const f = (at - s0) / (s1 - s0);
  return rgb(c0.map((v, i) => v + f * (c1[i] - v)));
}
const rgb = (c) => `rgb(${c.map((v) => Math.round(v)).join(",")})`;

// A side's segments: {side, index, a, b, mu, beta [deg]}; beta (§8): the angle of the normal into
// the chute from +x, the right side mirrored (0: vertical; > 0: faces upward). A segment with an
// end that is no [x, y] pair is left out (the others keep their index).
export function segments(world, side) {
  const points = Array.isArray(world?.[side]?.points) ? world[side].points : [];
  const mu = Array.isArray(world?.[side]?.mu) ? world[side].mu : [];
  const found = [];
  for (let i = 0; i + 1 < points.length; i++) {
    const a = points[i], b = points[i + 1];
    if (!isPoint(a) || !isPoint(b)) continue;
    const dx = (side === "left" ? 1 : -1) * (b[0] - a[0]), dy = b[1] - a[1];
    found.push({ side, index: i, a, b, mu: mu[i] ?? null, beta: Math.atan2(-dx, dy) * 180 / Math.PI });
  }
  return found;
}

// The unit normal into the chute, in wall coordinates.
function inward(segment) {
  const dx = segment.b[0] - segment.a[0], dy = segment.b[1] - segment.a[1];
  const length = Math.hypot(dx, dy) || 1;
  return segment.side === "left" ? [dy / length, -dx / length] : [-dy / length, dx / length];
}

export const isFoothold = (segment) => segment.mu !== 0 && Math.abs(segment.beta) >= 0.5;

// The extent of a world's points (x and y ranges), or a unit square where it has none.
export function extent(world) {
  const points = SIDES.flatMap((side) => (Array.isArray(world?.[side]?.points) ? world[side].points : [])).filter(isPoint);
  if (!points.length) return { xmin: -1, xmax: 1, ymin: 0, ymax: 1 };
  const xs = points.map((p) => p[0]), ys = points.map((p) => p[1]);
  const frame = { xmin: Math.min(...xs), xmax: Math.max(...xs), ymin: Math.min(...ys), ymax: Math.max(...ys) };
  if (frame.ymax - frame.ymin < 1e-9) frame.ymax = frame.ymin + 1;
  const pad = 0.08 * (frame.xmax - frame.xmin || 1);
  return { ...frame, xmin: frame.xmin - pad, xmax: frame.xmax + pad };
}

function niceStep(range, count) {
  const raw = range / count, power = 10 ** Math.floor(Math.log10(raw));
  return [1, 2, 5, 10].map((m) => m * power).find((step) => step >= raw);
}

// Draw ``world`` into ``svg`` (replacing what it held). Options: thumbnail (small, no axes, no
// vertices), frame (the extent to draw, e.g. kept while a vertex is dragged), selected ({side,
// index, vertex?}), error ({side, index, vertex?, message}: marked at its segment, the message
// beside it), clip (an id: the sides clipped to the frame, for a frame smaller than the world).
// Returns {frame, toWorld(clientX, clientY), toSvg(x, y): a world point's place in
// the drawing, for marks drawn over it (a plan's targets)}.
export function drawWorld(svg, world, options = {}) {
  const thumb = Boolean(options.thumbnail);
  const frame = options.frame ?? extent(world);
  const spanX = frame.xmax - frame.xmin, spanY = frame.ymax - frame.ymin;
  let scale, width, height, left, top;
  if (thumb) {
    width = options.width ?? 40; height = options.height ?? 60;
    scale = Math.min((width - 4) / spanX, (height - 4) / spanY);
    left = (width - scale * spanX) / 2; top = (height - scale * spanY) / 2;
  } else {
    height = EDITOR.height; top = EDITOR.top;
    scale = (height - EDITOR.top - EDITOR.bottom) / spanY;
    left = EDITOR.margin + EDITOR.axis;
    width = left + scale * spanX + EDITOR.margin;
  }
  const px = (x) => left + (x - frame.xmin) * scale, py = (y) => top + (frame.ymax - y) * scale;
  const units = world?.units === "m" ? "m" : "l0";
  svg.replaceChildren();
  for (const [name, value] of Object.entries({ viewBox: `0 0 ${width} ${height}`, width, height, role: "img" })) svg.setAttribute(name, String(value));
  svg.classList.add("world-svg");
  if (!thumb) svg.append(...axes(frame, px, py, left, top, scale, units));
  const all = SIDES.flatMap((side) => segments(world, side));
  const clipped = options.clip ? { "clip-path": `url(#${options.clip})` } : {};
  if (options.clip) {
    const clip = svgElement("clipPath", { id: options.clip });
    clip.append(svgElement("rect", { x: px(frame.xmin), y: py(frame.ymax), width: scale * spanX, height: scale * spanY }));
    svg.append(clip);
  }
  const mark = (spec, cls, widthPx) => all.filter((s) => spec && s.side === spec.side && s.index === segmentOf(spec))
    .map((s) => svgElement("line", { x1: px(s.a[0]), y1: py(s.a[1]), x2: px(s.b[0]), y2: py(s.b[1]), class: cls, "stroke-width": widthPx }));
  svg.append(...mark(options.error, "world-error-mark", 12), ...mark(options.selected, "world-selected-mark", 10));
  for (const s of all) {
    const line = svgElement("line", { x1: px(s.a[0]), y1: py(s.a[1]), x2: px(s.b[0]), y2: py(s.b[1]), class: "world-segment",
      stroke: muColor(s.mu), "stroke-width": thumb ? 1.5 : 4, "stroke-linecap": "round", "data-side": s.side, "data-index": s.index, ...clipped });
    if (s.mu === 0) line.setAttribute("stroke-dasharray", thumb ? "2 2" : "5 4");
    line.append(svgElement("title", {}, `${s.side} segment ${s.index}: mu ${muWords(s.mu)}, beta ${s.beta.toFixed(1)}°`));
    svg.append(line);
    if (isFoothold(s)) svg.append(...foothold(s, px, py, thumb).map((node) => attributesOf(node, clipped)));
  }
  if (!thumb) {
    for (const side of SIDES) {
      const points = Array.isArray(world?.[side]?.points) ? world[side].points : [];
      points.forEach((p, index) => {
        if (!isPoint(p)) return;
        const chosen = options.selected?.vertex && options.selected.side === side && options.selected.index === index;
        const wrong = options.error?.vertex && options.error.side === side && options.error.index === index;
        svg.append(svgElement("circle", { cx: px(p[0]), cy: py(p[1]), r: chosen ? 7 : 5, "data-side": side, "data-index": index,
          class: `world-vertex${chosen ? " chosen" : ""}${wrong ? " wrong" : ""}` }));
      });
    }
    if (options.error?.message) svg.append(callout(options.error, all, px, py, left, width));
  }
  const toWorld = (clientX, clientY) => {
    const at = new DOMPoint(clientX, clientY).matrixTransform(svg.getScreenCTM().inverse());
    return [frame.xmin + (at.x - left) / scale, frame.ymax - (at.y - top) / scale];
  };
  return { frame, toWorld, toSvg: (x, y) => [px(x), py(y)] };
}

const attributesOf = (node, values) => {
  for (const [name, value] of Object.entries(values)) node.setAttribute(name, value);
  return node;
};

// The segment a mark names: a vertex's is the segment ending at it (the first point: segment 0).
const segmentOf = (spec) => (spec.vertex ? Math.max(spec.index - 1, 0) : spec.index);

function foothold(s, px, py, thumb) {
  const [nx, ny] = inward(s), length = thumb ? 4 : 12;
  const mx = px((s.a[0] + s.b[0]) / 2), my = py((s.a[1] + s.b[1]) / 2);
  const ex = mx + nx * length, ey = my - ny * length;
  const colour = s.beta > 0 ? FACES_UP : FACES_DOWN;
  const tick = svgElement("line", { x1: mx, y1: my, x2: ex, y2: ey, stroke: colour, "stroke-width": thumb ? 1 : 2, class: "world-foothold" });
  tick.append(svgElement("title", {}, `foothold: ${s.side} segment ${s.index}, beta ${s.beta.toFixed(1)}° (${s.beta > 0 ? "faces up" : "faces down"})`));
  if (thumb) return [tick];
  return [tick, svgElement("text", { x: ex + nx * 3, y: ey - ny * 3 + 3, class: "world-beta", fill: colour,
    "text-anchor": s.side === "left" ? "start" : "end" }, `${s.beta > 0 ? "+" : ""}${s.beta.toFixed(0)}°`)];
}

function axes(frame, px, py, left, top, scale, units) {
  const nodes = [], bottom = py(frame.ymin), right = px(frame.xmax);
  const stepY = niceStep(frame.ymax - frame.ymin, 10), stepX = niceStep(frame.xmax - frame.xmin, 4);
  for (let y = Math.ceil(frame.ymin / stepY) * stepY; y <= frame.ymax + 1e-9; y += stepY) {
    nodes.push(svgElement("line", { x1: left, x2: right, y1: py(y), y2: py(y), class: "world-grid" }),
      svgElement("text", { x: left - 6, y: py(y) + 4, "text-anchor": "end", class: "world-tick" }, String(Number(y.toPrecision(4)))));
  }
  for (let x = Math.ceil(frame.xmin / stepX) * stepX; x <= frame.xmax + 1e-9; x += stepX) {
    nodes.push(svgElement("line", { x1: px(x), x2: px(x), y1: top, y2: bottom, class: "world-grid" }),
      svgElement("text", { x: px(x), y: bottom + 14, "text-anchor": "middle", class: "world-tick" }, String(Number(x.toPrecision(4)))));
  }
  nodes.push(svgElement("rect", { x: left, y: top, width: right - left, height: bottom - top, class: "world-frame" }),
    svgElement("text", { x: (left + right) / 2, y: bottom + 32, "text-anchor": "middle", class: "world-axis" }, `x [${units}]`),
    svgElement("text", { x: left - 34, y: top + 4, "text-anchor": "end", class: "world-axis" }, `y [${units}]`));
  return nodes;
}

// The message of an error, in the margin beside its side, a line to the segment it names.
function callout(error, all, px, py, left, width) {
  const segment = all.find((s) => s.side === error.side && s.index === segmentOf(error));
  const group = svgElement("g", { class: "world-error-callout" });
  const y = segment ? py((segment.a[1] + segment.b[1]) / 2) : 40;
  const onLeft = error.side !== "right";
  const x = onLeft ? left - 40 : width - EDITOR.margin + 10;
  // Long decimals shortened to 6 digits in the drawing (the list beside it keeps the service's words).
  const lines = wrap(String(error.message).replace(/-?\d+\.\d{7,}/g, (n) => String(Number(Number(n).toPrecision(6)))), 22);
  const text = svgElement("text", { x, y: y - 6 * (lines.length - 1), "text-anchor": onLeft ? "end" : "start", class: "world-error-text" });
  lines.forEach((line, i) => text.append(svgElement("tspan", { x, dy: i ? 13 : 0 }, line)));
  if (segment) {
    const mx = px((segment.a[0] + segment.b[0]) / 2);
    group.append(svgElement("line", { x1: onLeft ? x + 4 : x - 4, y1: y, x2: mx, y2: y, class: "world-error-leader" }));
  }
  group.append(text);
  return group;
}

function wrap(message, columns) {
  const lines = [];
  for (const word of String(message).split(/\s+/)) {
    const last = lines.at(-1);
    if (last !== undefined && (last + " " + word).length <= columns) lines[lines.length - 1] = `${last} ${word}`;
    else lines.push(word);
  }
  return lines.slice(0, 12);
}

// The friction scale and the foothold ticks, as a legend in ``svg``.
export function drawLegend(svg) {
  const gradient = svgElement("linearGradient", { id: "mu-scale" });
  for (const [stop, colour] of STOPS) gradient.append(svgElement("stop", { offset: stop, "stop-color": rgb(colour) }));
  const nodes = [svgElement("defs"), svgElement("text", { x: 6, y: 12, class: "world-axis" }, "friction mu"),
    svgElement("rect", { x: 6, y: 18, width: 150, height: 10, fill: "url(#mu-scale)" })];
  nodes[0].append(gradient);
  for (let mu = 0; mu <= MU_TOP; mu++) nodes.push(svgElement("text", { x: 6 + mu * 50, y: 40, "text-anchor": "middle", class: "world-tick" }, mu === MU_TOP ? `${mu}+` : String(mu)));
  const swatch = (x, y, colour, words, dashed) => [svgElement("line", { x1: x, x2: x + 22, y1: y, y2: y, stroke: colour, "stroke-width": 4,
    ...(dashed ? { "stroke-dasharray": "5 4" } : {}) }), svgElement("text", { x: x + 28, y: y + 4, class: "world-tick" }, words)];
  nodes.push(...swatch(180, 14, muColor(0), "0: no grip", true), ...swatch(180, 34, MODEL_MU_COLOR, "null: the model's mu"),
    ...swatch(180, 54, NO_SLIP_COLOR, "inf: no slip"), ...swatch(6, 64, FACES_UP, "foothold: faces up (β > 0)"),
    ...swatch(6, 84, FACES_DOWN, "foothold: faces down (β < 0)"));
  for (const [name, value] of Object.entries({ viewBox: "0 0 330 92", width: 330, height: 92, role: "img" })) svg.setAttribute(name, String(value));
  svg.replaceChildren(...nodes);
}
