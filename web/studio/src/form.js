// Plain HTML forms generated from the scene's JSON Schema (GET /api/schema, `navsim schema`).
// Every leaf gets a native control (keyboard and screen-reader friendly): numbers with their
// bounds and unit (x-unit), enums as selects, 3-vectors as three numbers, lists of mappings as
// item groups with Add/Remove. An empty control means "not in the file" (the reader's default,
// shown as the placeholder). Kind-dependent keys (allOf: if {K: const} then {...}) appear for the
// kind the scene has.

const isObj = (v) => v !== null && typeof v === 'object' && !Array.isArray(v);
const types = (s) => (Array.isArray(s.type) ? s.type : s.type ? [s.type] : []);
let uid = 0;
const newId = (p) => `f${++uid}-${p.join('-').replace(/[^A-Za-z0-9_-]/g, '_')}`;

// $ref inside the same document ("#/$defs/x").
export function deref(root, s) {
  let guard = 0;
  while (s && s.$ref && guard++ < 16) {
    const parts = s.$ref.replace(/^#\//, '').split('/');
    let t = root;
    for (const p of parts) t = t ? t[p.replace(/~1/g, '/').replace(/~0/g, '~')] : undefined;
    s = t ? { ...t, ...s, $ref: undefined } : s;
    if (!t) break;
  }
  return s;
}

// Properties of an object schema for the current value: its own, plus those of the allOf/if-then
// branches whose condition the value meets (and anyOf/oneOf branches, all shown).
export function objectProperties(root, s, value) {
  s = deref(root, s);
  const props = { ...(s.properties || {}) };
  for (const alt of [...(s.anyOf || []), ...(s.oneOf || [])]) Object.assign(props, deref(root, alt).properties || {});
  for (const branch of s.allOf || []) {
    const b = deref(root, branch);
    if (b.if && b.then && b.if.properties) {
      let ok = true;
      for (const [k, cond] of Object.entries(b.if.properties)) {
        const v = isObj(value) && value[k] !== undefined ? value[k] : deref(root, props[k] || {}).default;
        if (cond.const !== undefined && v !== cond.const) ok = false;
        if (cond.enum && !cond.enum.includes(v)) ok = false;
      }
      if (ok) Object.assign(props, deref(root, b.then).properties || {});
    } else if (b.properties) Object.assign(props, b.properties);
  }
  return props;
}

// Walk the schema along a path of keys (numbers index arrays).
export function schemaAt(root, path, scene) {
  let s = root;
  for (let i = 0; i < path.length; ++i) {
    s = deref(root, s);
    const k = path[i];
    if (typeof k === 'number') s = s.items;
    else s = objectProperties(root, s, scene.get(path.slice(0, i)))[k];
    if (!s) return null;
  }
  return deref(root, s);
}

function isNumberSchema(s) {
  const t = types(s);
  return t.includes('number') || t.includes('integer');
}
function isVectorSchema(root, s) {
  const t = types(s);
  if (!t.includes('array') || !s.items) return false;
  const it = deref(root, s.items);
  return types(it).length > 0 && types(it).every((x) => x === 'number' || x === 'integer') &&
    (s.maxItems === undefined || s.maxItems <= 6);
}

function label(key, s) {
  const el = document.createElement('span');
  el.className = 'key';
  el.textContent = String(key);
  if (s.description) el.title = s.description;
  return el;
}
function unit(s) {
  const u = s['x-unit'] || (s.items && s.items['x-unit']);
  const el = document.createElement('span');
  el.className = 'unit';
  el.textContent = u ? u : '';
  return el;
}
function describe(input, s) {
  const bits = [];
  if (s.description) bits.push(s.description);
  if (s.minimum !== undefined || s.maximum !== undefined) bits.push(`range ${s.minimum ?? '−∞'} … ${s.maximum ?? '∞'}`);
  if (s.default !== undefined) bits.push(`default ${JSON.stringify(s.default)}`);
  if (bits.length) input.title = bits.join('; ');
}
function numberInput(s, value, onValue, aria) {
  const inp = document.createElement('input');
  inp.type = 'number';
  inp.step = 'any';
  if (s.minimum !== undefined && Number.isFinite(s.minimum)) inp.min = s.minimum;
  if (s.maximum !== undefined && Number.isFinite(s.maximum)) inp.max = s.maximum;
  if (typeof value === 'number') inp.value = String(value);
  if (typeof s.default === 'number') inp.placeholder = String(s.default);
  inp.setAttribute('aria-label', aria);
  describe(inp, s);
  inp.addEventListener('input', () => {
    if (inp.value === '') onValue(undefined);
    else if (Number.isFinite(inp.valueAsNumber)) onValue(types(s).includes('integer') && !types(s).includes('number') ? Math.round(inp.valueAsNumber) : inp.valueAsNumber);
  });
  return inp;
}

// Render the schema node s (value at path) into parent. scene: {get(path), set(path, v), del(path)}.
// onStructure: called when the set of fields may change (kind switch, item added/removed).
export function renderNode(parent, root, s, key, path, scene, onStructure, skip = null) {
  s = deref(root, s);
  const value = scene.get(path);
  const t = types(s);
  const set = (v) => (v === undefined ? scene.del(path) : scene.set(path, v));
  const row = document.createElement('div');
  row.className = 'field';
  const id = newId(path);

  if (s.properties || s.allOf || (t.includes('object') && !t.includes('array'))) {
    const fs = document.createElement('fieldset');
    const lg = document.createElement('legend');
    lg.textContent = String(key);
    if (s.description) lg.title = s.description;
    fs.appendChild(lg);
    const props = objectProperties(root, s, value);
    // Of two spellings of one quantity (allOf: not both required, e.g. lat_deg / lat_rad) the
    // second is shown only when the scene uses it.
    const hidden = new Set();
    for (const b of s.allOf || []) {
      const pair = b.not && b.not.required;
      if (Array.isArray(pair) && pair.length === 2 && !(isObj(value) && value[pair[1]] !== undefined)) hidden.add(pair[1]);
    }
    for (const [k, ps] of Object.entries(props)) if (!hidden.has(k) && !(skip && skip.includes(k))) renderNode(fs, root, ps, k, [...path, k], scene, onStructure);
    if (Array.isArray(value) || (value !== undefined && !isObj(value))) {
      const p = document.createElement('p');
      p.className = 'hint';
      p.textContent = 'this value is written in a short form; edit it in the YAML view';
      fs.appendChild(p);
    }
    parent.appendChild(fs);
    return;
  }
  if (s.enum) {
    const sel = document.createElement('select');
    sel.id = id;
    const def = document.createElement('option');
    def.value = '';
    def.textContent = s.default !== undefined ? `(default: ${s.default})` : '(not set)';
    sel.appendChild(def);
    for (const e of s.enum) {
      const o = document.createElement('option');
      o.value = String(e);
      o.textContent = String(e);
      sel.appendChild(o);
    }
    sel.value = value === undefined ? '' : String(value);
    describe(sel, s);
    sel.addEventListener('change', () => {
      set(sel.value === '' ? undefined : sel.value);
      onStructure();
    });
    const l = label(key, s);
    l.id = id + '-l';
    sel.setAttribute('aria-labelledby', l.id);
    row.append(l, sel);
    parent.appendChild(row);
    return;
  }
  if (isVectorSchema(root, s)) {
    const n = s.maxItems || s.minItems || 3;
    const it = deref(root, s.items);
    const box = document.createElement('span');
    box.className = 'vec';
    const cur = Array.isArray(value) ? value.slice() : typeof value === 'number' ? [value] : [];
    const inputs = [];
    for (let i = 0; i < n; ++i) {
      const inp = numberInput({ ...it, default: Array.isArray(s.default) ? s.default[i] : s.default },
        cur[i], () => {
          const vals = inputs.map((x) => (x.value === '' ? undefined : x.valueAsNumber));
          if (vals.every((v) => v === undefined)) set(undefined);
          else if (t.includes('number') && vals.slice(1).every((v) => v === undefined)) set(vals[0]);
          else set(vals.map((v, j) => (v === undefined ? (Array.isArray(s.default) ? s.default[j] : 0) : v)));
        }, `${key} [${i}]`);
      inputs.push(inp);
      box.appendChild(inp);
    }
    box.appendChild(unit(s));
    row.append(label(key, s), box);
    parent.appendChild(row);
    return;
  }
  if (t.includes('array') && s.items) {
    const it = deref(root, s.items);
    const fs = document.createElement('fieldset');
    const lg = document.createElement('legend');
    lg.textContent = String(key);
    if (s.description) lg.title = s.description;
    fs.appendChild(lg);
    const list = Array.isArray(value) ? value : [];
    list.forEach((_, i) => {
      const item = document.createElement('div');
      item.className = 'item';
      renderNode(item, root, it, `${key}[${i}]`, [...path, i], scene, onStructure);
      const rm = document.createElement('button');
      rm.type = 'button';
      rm.textContent = `Remove ${key}[${i}]`;
      rm.addEventListener('click', () => {
        const cur = scene.get(path) || [];
        const next = cur.filter((__, j) => j !== i);
        set(next.length ? next : undefined);
        onStructure();
      });
      item.appendChild(rm);
      fs.appendChild(item);
    });
    if (s.maxItems === undefined || list.length < s.maxItems) {
      const add = document.createElement('button');
      add.type = 'button';
      add.textContent = `Add ${key}`;
      add.addEventListener('click', () => {
        scene.set([...path, list.length], newItem(root, it));
        onStructure();
      });
      fs.appendChild(add);
    }
    parent.appendChild(fs);
    return;
  }
  if (isNumberSchema(s)) {
    const box = document.createElement('span');
    const inp = numberInput(s, value, set, String(key));
    inp.id = id;
    box.append(inp, unit(s));
    row.append(label(key, s), box);
    parent.appendChild(row);
    return;
  }
  if (t.includes('boolean')) {
    const sel = document.createElement('select');
    sel.id = id;
    for (const [v, txt] of [['', s.default !== undefined ? `(default: ${s.default})` : '(not set)'], ['true', 'true'], ['false', 'false']]) {
      const o = document.createElement('option');
      o.value = v;
      o.textContent = txt;
      sel.appendChild(o);
    }
    sel.value = value === undefined ? '' : String(value);
    sel.setAttribute('aria-label', String(key));
    describe(sel, s);
    sel.addEventListener('change', () => set(sel.value === '' ? undefined : sel.value === 'true'));
    row.append(label(key, s), sel);
    parent.appendChild(row);
    return;
  }
  // Strings and anything else: a text field (values that are not plain text go to the YAML view).
  const inp = document.createElement('input');
  inp.type = 'text';
  inp.id = id;
  if (value !== undefined && typeof value !== 'object') inp.value = String(value);
  else if (value !== undefined) {
    inp.value = JSON.stringify(value);
    inp.readOnly = true;
  }
  if (s.default !== undefined) inp.placeholder = String(s.default);
  if (s.maxLength) inp.maxLength = s.maxLength;
  inp.setAttribute('aria-label', String(key));
  describe(inp, s);
  inp.addEventListener('input', () => set(inp.value === '' ? undefined : inp.value));
  row.append(label(key, s), inp);
  parent.appendChild(row);
}

// A new list item: the required keys with their defaults (or zeros).
export function newItem(root, s) {
  s = deref(root, s);
  if (isVectorSchema(root, s)) return new Array(s.maxItems || s.minItems || 2).fill(0);
  if (!(s.properties || s.allOf)) return s.default !== undefined ? s.default : isNumberSchema(s) ? 0 : '';
  const props = objectProperties(root, s, {});
  const out = {};
  for (const k of s.required || []) {
    const ps = deref(root, props[k] || {});
    out[k] = ps.default !== undefined ? ps.default : ps.enum ? ps.enum[0] : isNumberSchema(ps) ? 0 : '';
  }
  return out;
}
