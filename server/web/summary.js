// What a person reads first about a finished job: the key figures of the
// diagnostics, each judged against the product's targets (green: met, amber:
// close, red: missed), and the pipeline's stages in the order data flows
// through them (the worker reports them as they finish, which with parallel
// branches is not that order).

// [label, value from the diagnostics, format, judge -> 'good' | 'near' | 'bad' | '']
const FIGURES = [
  ['Continuity', (d) => d.uv?.continuity, (v) => v.toFixed(3), (v) => (v >= 0.95 ? 'good' : v >= 0.85 ? 'near' : 'bad'), 'target ≥ 0.95'],
  ['UV islands', (d) => d.uv?.islands, (v) => String(v), () => '', ''],
  ['Overlap', (d) => d.uv?.overlap, (v) => `${(v * 100).toFixed(2)} %`, (v) => (v <= 0.001 ? 'good' : v <= 0.01 ? 'near' : 'bad'), 'target ≤ 0.1 %'],
  ['Utilisation', (d) => d.uv?.utilisation, (v) => `${(v * 100).toFixed(1)} %`, (v) => (v >= 0.55 ? 'good' : v >= 0.4 ? 'near' : 'bad'), 'target ≥ 55 %'],
  ['Stretch (L2)', (d) => d.uv?.stretch_l2, (v) => v.toFixed(3), (v) => (v <= 1.3 ? 'good' : v <= 1.6 ? 'near' : 'bad'), 'target ≤ 1.3'],
  ['Flipped triangles', (d) => d.uv?.flipped_fraction, (v) => `${(v * 100).toFixed(2)} %`, (v) => (v <= 0.005 ? 'good' : v <= 0.02 ? 'near' : 'bad'), 'target ≤ 0.5 %'],
  ['Time', (d) => d.seconds ?? sumStages(d.stages), (v) => `${v.toFixed(1)} s`, () => '', ''],
  ['Triangles', (d) => d.soup?.triangles, (v) => v.toLocaleString('en'), () => '', ''],
  ['Texture', (d) => d.output?.texture?.source, (v) => ({ rebake: 're-baked from the input', uv_check: 'UV check', user: 'your image' }[v] || v), () => '', ''],
  ['Warnings', (d) => d.warnings?.length, (v) => String(v), (v) => (v === 0 ? 'good' : 'near'), 'see the list below'],
];

function sumStages(stages) {
  return Object.values(stages || {}).reduce((s, x) => s + (x?.seconds || 0), 0);
}

// One row per figure the diagnostics have: <tr class="good|near|bad">.
export function renderSummary(table, diag) {
  const body = table.querySelector('tbody');
  body.textContent = '';
  for (const [label, get, format, judge, target] of FIGURES) {
    const v = get(diag);
    if (v === undefined || v === null) continue;
    const tr = body.insertRow();
    tr.className = judge(v);
    tr.insertCell().textContent = label;
    tr.insertCell().textContent = format(v);
    tr.insertCell().textContent = target;
  }
}

// Data-flow order of the worker's stage names (prefix match; parallel branches
// proxy/atlas and charge/trace side by side, as docs/architecture.md draws them).
// The job's stage_seconds object comes with its keys sorted, so the steps
// inside a stage are named here in their order too.
const ORDER = ['load', 'intersections', 'proxy', 'charge', 'trace', 'atlas', 'transfer', 'weld',
  'uv_solve', 'box', 'metrics', 'report', 'write', 'done'];
const STEPS = ['narrow_band', 'marching_cubes', 'components', 'smoothing', 'remeshing', 'collapsing_short_edges',
  'checks', 'segment', 'parameterize', 'merge', 'relax', 'pack', 'measure', 'done'];

export function stageRank(name) {
  const i = ORDER.findIndex((p) => name === p || name.startsWith(`${p}_`));
  if (i < 0) return ORDER.length;
  const step = name.slice(ORDER[i].length).replace(/^_+/, '');
  const j = STEPS.indexOf(step);
  return i + (step ? (j < 0 ? STEPS.length : j) + 1 : 0) / (STEPS.length + 2);
}

// [name, seconds] pairs in pipeline order (ties keep the reported order).
export function orderedStages(stageSeconds) {
  return Object.entries(stageSeconds || {})
    .map((e, i) => [e, i])
    .sort((a, b) => stageRank(a[0][0]) - stageRank(b[0][0]) || a[1] - b[1])
    .map(([e]) => e);
}
