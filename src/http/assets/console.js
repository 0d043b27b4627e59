// plcemu console: one script for every page, chosen by <body data-page="...">.
// Everything the server sends (names, values, errors) goes into the page as text
// (textContent, input values, attributes), never as HTML.
'use strict';

(() => {
  const page = document.body.dataset.page || '';
  const TOKEN_KEY = 'plcemu.token';
  const VIEWS = [
    ['devices', 'Devices'],
    ['loops', 'Loops'],
    ['plant', 'Plant'],
    ['traffic', 'Traffic'],
  ];
  const FAULTS = [
    ['sensor_broken', 'sensor broken'],
    ['heater_open', 'heater open'],
    ['heater_shorted', 'heater shorted'],
    ['reading_frozen', 'reading frozen'],
  ];
  // Communication faults (docs/communication-faults.md): the fields a PUT takes. A PUT replaces
  // the whole set (a field left out is off), so the plant page sends every field it wants.
  const COMM_FIELDS = ['delay_ms', 'drop_every', 'drop_probability', 'seed', 'exception', 'offline',
    'refuse_connections', 'disconnect_after', 'reset', 'garble', 'stop', 'unit', 'function', 'from', 'count'];
  const COMM_FIGURES = ['delayed', 'dropped', 'refused', 'silenced', 'disconnected', 'garbled'];
  // 300 -> "300", [100, 300] -> "100-300".
  const fmtDelay = (d) => (Array.isArray(d) ? d.join('-') : String(d));
  const delayOn = (s) => (Array.isArray(s.delay_ms) ? s.delay_ms[1] > 0 : Number(s.delay_ms) > 0);
  const exceptionOn = (s) => Number(s.exception) > 0;
  // The plant page's buttons, a preset each: label(form) its text (the delay and the code come
  // from the form), lit(state) whether the fault is on, set(body, form, on) switches it.
  const COMM_FAULTS = [
    {key: 'delay', label: (f) => 'Delay ' + (f.delay === null ? 'N' : fmtDelay(f.delay)) + ' ms',
      title: 'Every reply held this long (the Delay field), on its connection only',
      lit: delayOn,
      set: (b, f, on) => {
        b.delay_ms = on ? f.delay : 0;
      }},
    {key: 'drop', label: () => 'Drop every 2nd', title: 'Every 2nd request gets no answer (it is served; its answer is lost)',
      lit: (s) => Number(s.drop_every) > 0 || Number(s.drop_probability) > 0,
      set: (b, f, on) => {
        b.drop_every = on ? 2 : 0;
        b.drop_probability = 0;
      }},
    {key: 'exception', label: (f) => 'Exception ' + (f.exception === null ? 'N' : hex2(f.exception)),
      title: 'Answered with this exception code (the Exception field), nothing read or written',
      lit: exceptionOn,
      set: (b, f, on) => {
        b.exception = on ? f.exception : 0;
      }},
    {key: 'offline', label: () => 'Offline', title: 'Nothing answered, nothing served; TCP connections stay open',
      lit: (s) => !!s.offline,
      set: (b, f, on) => {
        b.offline = on;
      }},
    {key: 'refuse', label: () => 'Refuse connections', title: 'New TCP connections refused, and those open answered nothing (offline too): a PLC switched off',
      lit: (s) => !!s.refuse_connections,
      set: (b, f, on) => {
        b.refuse_connections = on;
        b.offline = on;
      }},
    {key: 'disconnect', label: () => 'Disconnect', title: 'A TCP connection is closed at its next request, without an answer',
      lit: (s) => s.disconnect_after !== null && s.disconnect_after !== undefined,
      set: (b, f, on) => {
        if (on) {
          b.disconnect_after = 0;
        } else {
          delete b.disconnect_after;
          b.reset = false;
        }
      }},
    {key: 'garble', label: () => 'Garble CRC', title: 'Serial lines: replies with a wrong checksum (TCP and UDP replies are never garbled)',
      lit: (s) => !!s.garble && s.garble !== 'none',
      set: (b, f, on) => {
        b.garble = on ? 'crc' : 'none';
      }},
    {key: 'stop', label: () => 'Stop', title: 'The PLC leaves RUN: the program stops, outputs go off',
      lit: (s) => !!s.stop,
      set: (b, f, on) => {
        b.stop = on;
      }},
  ];

  // ---- Small helpers ------------------------------------------------------------------------

  const byId = (id) => document.getElementById(id);

  // el('td', {className: 'num', text: '12', dataset: {device: 'R100'}, attrs: {scope: 'row'}}, child...)
  function el(tag, opts = {}, ...children) {
    const e = document.createElement(tag);
    if (opts.className) e.className = opts.className;
    if (opts.text !== undefined) e.textContent = String(opts.text);
    for (const [k, v] of Object.entries(opts.dataset || {})) e.dataset[k] = String(v);
    for (const [k, v] of Object.entries(opts.attrs || {})) e.setAttribute(k, String(v));
    for (const c of children) e.append(c);
    return e;
  }

  // Sets an element's text only when it changed (keeps selections and screen readers calm).
  function setText(e, text) {
    const s = String(text);
    if (e.textContent !== s) e.textContent = s;
  }

  // Keeps a tbody's rows in step with a list: rows are made once per key, updated in place,
  // put in the list's order, and dropped with their item. `empty` is the row shown for none.
  function syncRows(tbody, rows, items, keyOf, make, update, empty) {
    const seen = new Set();
    const wanted = items.map((item) => {
      const key = keyOf(item);
      seen.add(key);
      let r = rows.get(key);
      if (!r) {
        r = make(item);
        rows.set(key, r);
      }
      update(r, item);
      return r.tr;
    });
    for (const key of [...rows.keys()]) {
      if (!seen.has(key)) rows.delete(key);
    }
    const shown = wanted.length ? wanted : [empty];
    const now = [...tbody.children];
    if (now.length !== shown.length || now.some((tr, i) => tr !== shown[i])) tbody.replaceChildren(...shown);
  }

  const emptyRow = (text, columns) => el('tr', {className: 'empty'}, el('td', {className: 'hint', text, attrs: {colspan: columns}}));

  // A client of a PLC as a clients table shows it (the overview's and the traffic page's):
  // r = {tr, cells: {peer, protocol, requests, refusals, last}}.
  const CLIENT_FIELDS = ['peer', 'protocol', 'requests', 'refusals', 'last'];

  function clientCells() {
    const cells = {};
    for (const f of CLIENT_FIELDS) {
      cells[f] = el('td', {className: f === 'requests' || f === 'refusals' ? 'num' : f === 'peer' ? 'mono' : '', dataset: {field: f}});
    }
    return cells;
  }

  function showClient(cells, c) {
    setText(cells.peer, c.peer || '—');
    setText(cells.protocol, c.protocol || '—');
    setText(cells.requests, c.requests);
    setText(cells.refusals, c.refusals);
    cells.refusals.classList.toggle('bad', Number(c.refusals) > 0);
    setText(cells.last, fmtClock(c.last));
    cells.last.title = c.last || '';
  }

  // The PLC of a PLC page: /plcs/{plc}/{view}.
  function plcFromPath() {
    const m = /^\/plcs\/([^/]+)\/[^/]+\/?$/.exec(location.pathname);
    if (!m) return null;
    try {
      return decodeURIComponent(m[1]);
    } catch (e) {
      return m[1];
    }
  }

  const plc = plcFromPath();
  // Why this page's PLC is not there (the API's 404), once the heading's request found it out.
  let plcUnknown = null;
  const plcUrl = (p) => '/plcs/' + encodeURIComponent(p);
  const apiPlc = (p) => '/api/v1/plcs/' + encodeURIComponent(p);

  // ---- Messages and status ------------------------------------------------------------------

  const messageBox = byId('message');

  // kind: 'error' (a refusal: the server's own words), 'ok', or '' to clear.
  function say(text, kind) {
    if (!messageBox) return;
    messageBox.textContent = text || '';
    messageBox.className = 'message' + (kind ? ' ' + kind : '');
    messageBox.setAttribute('role', kind === 'error' ? 'alert' : 'status');
    messageBox.hidden = !text;
  }

  function setStatus(text, kind) {
    const s = byId('status');
    if (!s) return;
    setText(s, text);
    s.className = 'status' + (kind ? ' ' + kind : '');
  }

  // ---- Talking to the API -------------------------------------------------------------------

  class ApiError extends Error {
    constructor(message, status) {
      super(message);
      this.status = status;
    }
  }

  function token() {
    try {
      return sessionStorage.getItem(TOKEN_KEY) || '';
    } catch (e) {
      return '';
    }
  }

  // The token field: entered once, kept for this tab (sessionStorage), sent with every write.
  function initToken() {
    const input = byId('token');
    if (!input) return;
    const form = byId('token-form');
    if (form) form.addEventListener('submit', (ev) => ev.preventDefault());
    input.value = token();
    input.addEventListener('input', () => {
      const v = input.value.trim();
      try {
        if (v) {
          sessionStorage.setItem(TOKEN_KEY, v);
        } else {
          sessionStorage.removeItem(TOKEN_KEY);
        }
      } catch (e) {
        // Storage refused (private mode): the field still works for this page.
      }
    });
  }

  // A GET, or a write (PUT, DELETE): the token when there is one, and `body` as JSON when given
  // (a DELETE has none).
  async function request(method, path, body) {
    // An unknown PLC's page asks no more after the first answer said so: nothing will change.
    if (plcUnknown !== null && (path === apiPlc(plc) || path.startsWith(apiPlc(plc) + '/'))) {
      throw new ApiError(plcUnknown, 404);
    }
    const headers = {Accept: 'application/json'};
    const init = {method, headers, cache: 'no-store', credentials: 'same-origin'};
    if (method !== 'GET' && method !== 'HEAD') {
      const field = byId('token');
      const t = field ? field.value.trim() : token();
      if (t) headers.Authorization = 'Bearer ' + t;
    }
    if (body !== undefined) {
      headers['Content-Type'] = 'application/json';
      init.body = JSON.stringify(body);
    }
    let res;
    try {
      res = await fetch(path, init);
    } catch (e) {
      throw new ApiError('plcemud does not answer (' + e.message + ')', 0);
    }
    const text = await res.text();
    let data = null;
    try {
      data = JSON.parse(text);
    } catch (e) {
      data = null;
    }
    if (!res.ok) {
      let why = data && typeof data.error === 'string' ? data.error : 'HTTP ' + res.status;
      if (res.status === 401) why += ' (enter the console\'s token in "Write token")';
      throw new ApiError(why, res.status);
    }
    if (data === null || typeof data !== 'object') {
      throw new ApiError('the answer to ' + method + ' ' + path + ' is not JSON', res.status);
    }
    return data;
  }

  // An EventSource with its status line; handlers get the parsed JSON of each named event.
  function live(url, handlers) {
    const es = new EventSource(url);
    es.addEventListener('open', () => setStatus('Live', 'live'));
    es.addEventListener('error', () => {
      if (es.readyState === EventSource.CLOSED) {
        setStatus('Live updates stopped: reload the page', 'down');
      } else {
        setStatus('Connection to plcemud lost: reconnecting…', 'down');
      }
    });
    for (const [name, fn] of Object.entries(handlers)) {
      es.addEventListener(name, (ev) => {
        let data;
        try {
          data = JSON.parse(ev.data);
        } catch (e) {
          return;
        }
        fn(data);
      });
    }
    es.addEventListener('gone', (ev) => {
      let why = 'this stream ended';
      try {
        why = JSON.parse(ev.data).error || why;
      } catch (e) {
        // keep the generic text
      }
      es.close();
      say(why, 'error');
      setStatus('Live updates stopped', 'down');
    });
    window.addEventListener('pagehide', () => es.close());
    return es;
  }

  // ---- Formatting ---------------------------------------------------------------------------

  function fmtNumber(x, digits) {
    return typeof x === 'number' && Number.isFinite(x) ? x.toFixed(digits) : '—';
  }

  function fmtScale(x) {
    if (typeof x !== 'number') return '—';
    return '×' + (Number.isInteger(x) ? String(x) : String(Number(x.toFixed(3))));
  }

  function fmtTime(t) {
    if (!t) return '—';
    return [fmtScale(t.scale), t.frozen ? 'frozen' : 'running', fmtNumber(t.simulated_s, 1) + ' s'].join(' · ');
  }

  // "2026-11-28T13:05:00.123Z" -> "13:05:00.123" (the browser's time zone); the text as it is
  // when it is not a time.
  function fmtClock(iso) {
    if (!iso) return '—';
    const d = new Date(iso);
    if (Number.isNaN(d.getTime())) return String(iso);
    const two = (n) => String(n).padStart(2, '0');
    return two(d.getHours()) + ':' + two(d.getMinutes()) + ':' + two(d.getSeconds()) + '.' +
      String(d.getMilliseconds()).padStart(3, '0');
  }

  // Scan lateness: "120 / 850 µs" (99th percentile / worst).
  function fmtLateness(p) {
    const us = (x) => (typeof x === 'number' && Number.isFinite(x) ? String(Math.round(x)) : '—');
    return us(p.lateness_p99_us) + ' / ' + us(p.lateness_max_us) + ' µs';
  }

  // A page's refresh: one GET of `path` at a time, its answer handed to apply(data) unless a
  // write began while it was out (`writes()` counts them: that answer may show the state from
  // before the write); `status(data)` is then the status line. Returns the function to call.
  function poller(path, writes, apply, status) {
    let busy = false;
    return async function poll() {
      if (busy) return;
      busy = true;
      const seen = writes();
      try {
        const data = await request('GET', path);
        if (seen === writes()) {
          apply(data);
          setStatus(status(data), 'live');
        }
      } catch (e) {
        setStatus(e.message, 'down');
      } finally {
        busy = false;
      }
    };
  }

  // Values edited in place (the devices page's cells, a faceplate's set point and parameters),
  // for every input with a data-device under `container`: Enter writes it (`write(input)`),
  // Escape puts the live value back (`restore(input)`), and so does leaving it without Enter.
  function editInPlace(container, write, restore) {
    container.addEventListener('keydown', (ev) => {
      const input = ev.target;
      if (!(input instanceof HTMLInputElement) || !input.dataset.device) return;
      if (ev.key === 'Enter') {
        ev.preventDefault();
        write(input);
      } else if (ev.key === 'Escape') {
        ev.preventDefault();
        restore(input);
        input.select();
      }
    });
    container.addEventListener('input', (ev) => {
      if (ev.target instanceof HTMLInputElement) ev.target.classList.add('edited');
    });
    container.addEventListener('focusin', (ev) => {
      if (ev.target instanceof HTMLInputElement) ev.target.select();
    });
    container.addEventListener('focusout', (ev) => {
      const input = ev.target;
      if (input instanceof HTMLInputElement && input.dataset.device && !input.hasAttribute('aria-busy')) {
        restore(input);
      }
    });
  }

  const signed16 = (v) => (v >= 0x8000 ? v - 0x10000 : v);
  const hex16 = (v) => '0x' + v.toString(16).toUpperCase().padStart(4, '0');
  const hex2 = (v) => v.toString(16).toUpperCase().padStart(2, '0');
  const bits16 = (v) => v.toString(2).padStart(16, '0').replace(/(\d{4})(?=\d)/g, '$1 ');
  // A device of two words (a 32-bit counter) reads as one 32-bit value.
  const signedOf = (v, words) => (words === 2 ? (v >= 0x80000000 ? v - 0x100000000 : v) : signed16(v));
  const hexOf = (v, words) => (words === 2 ? '0x' + v.toString(16).toUpperCase().padStart(8, '0') : hex16(v));
  const bitsOf = (v, words) =>
    words === 2 ? v.toString(2).padStart(32, '0').replace(/(\d{4})(?=\d)/g, '$1 ') : bits16(v);

  // "1234", "-5", "+7", "0x1F", "-0x10" -> a number; anything else -> null.
  function parseValue(text) {
    const s = text.trim();
    let m = /^([+-]?)(\d+)$/.exec(s);
    let v = null;
    if (m) v = parseInt(m[2], 10);
    m = /^([+-]?)0x([0-9a-f]+)$/i.exec(s);
    if (m) v = parseInt(m[2], 16);
    if (v === null || !Number.isSafeInteger(v)) return null;
    return s.startsWith('-') ? -v : v;
  }

  // ---- Nav bar and title --------------------------------------------------------------------

  function initNav() {
    const nav = byId('nav');
    if (!nav) return;
    const home = nav.querySelector('a[href="/"]');
    if (home && page === 'overview') home.setAttribute('aria-current', 'page');
    if (plc === null) return;
    nav.append(el('span', {className: 'plc', text: 'PLC ' + plc, attrs: {title: 'This PLC\'s pages'}}));
    for (const [view, label] of VIEWS) {
      const a = el('a', {text: label, attrs: {href: plcUrl(plc) + '/' + view}});
      if (view === page) a.setAttribute('aria-current', 'page');
      nav.append(a);
    }
    const name = VIEWS.find(([view]) => view === page);
    document.title = (name ? name[1] : page) + ' · PLC ' + plc + ' · plcemu';
  }

  // "PLC kiln · fbs FBs-24MC · station 1 · RUN" beside a PLC page's heading.
  function describePlc(p) {
    const span = byId('plc-name');
    if (!span || !p) return;
    const parts = ['PLC ' + p.id, [p.profile, p.model].filter(Boolean).join(' '), 'station ' + p.station];
    parts.push(p.running ? 'RUN' : 'STOP');
    setText(span, parts.join(' · '));
  }

  async function loadPlcHeading() {
    try {
      describePlc(await request('GET', apiPlc(plc)));
    } catch (e) {
      if (e.status === 404) plcUnknown = e.message;
      say(e.message, 'error');
    }
  }

  // ---- Overview -----------------------------------------------------------------------------

  function overview() {
    const tbody = document.querySelector('#plcs tbody');
    const rows = new Map();
    let order = null;

    function makeRow(p) {
      const link = el('a', {text: p.id, attrs: {href: plcUrl(p.id) + '/devices'}});
      const head = el('th', {attrs: {scope: 'row'}}, link);
      const label = el('div', {className: 'hint'});
      head.append(label);
      const cell = (field, className) => el('td', {className: className || '', dataset: {field}});
      const cells = {
        profile: cell('profile'),
        model: cell('model'),
        station: cell('station', 'num'),
        listeners: cell('listeners'),
        scan_ms: cell('scan_ms', 'num'),
        running: cell('running'),
        scans: cell('scans', 'num'),
        lateness: cell('lateness', 'num'),
        time: cell('time'),
      };
      const badge = el('span', {className: 'badge'});
      cells.running.append(badge);
      const links = el('div', {className: 'links'});
      for (const [view, text] of VIEWS) {
        links.append(el('a', {text, attrs: {href: plcUrl(p.id) + '/' + view}}));
      }
      const tr = el('tr', {dataset: {plc: p.id}}, head, ...Object.values(cells), el('td', {}, links));
      return {tr, label, cells, badge};
    }

    function update(r, p) {
      setText(r.label, p.label || '');
      r.label.hidden = !p.label;
      setText(r.cells.profile, p.profile);
      setText(r.cells.model, p.model);
      setText(r.cells.station, p.station);
      const listeners = String(p.listeners || '—');
      if (r.cells.listeners.dataset.text !== listeners) {
        // "http 127.0.0.1:8020, tcp 127.0.0.1:5020": one a line.
        r.cells.listeners.dataset.text = listeners;
        r.cells.listeners.replaceChildren(...listeners.split(', ').map((l) => el('div', {text: l})));
      }
      // "10 ms / 145 µs": the scan period, and what a scan takes on average.
      setText(r.cells.scan_ms, p.scan_ms + ' ms' +
        (typeof p.scan_us === 'number' ? ' / ' + Math.round(p.scan_us) + ' µs' : ''));
      setText(r.badge, p.running ? 'RUN' : 'STOP');
      r.badge.className = 'badge ' + (p.running ? 'run' : 'stop');
      setText(r.cells.scans, p.scans);
      setText(r.cells.lateness, fmtLateness(p));
      setText(r.cells.time, fmtTime(p.time));
    }

    // Every PLC's clients, in one table: a row per (PLC, peer).
    const clientsBody = document.querySelector('#clients tbody');
    const clientRows = new Map();
    const noClients = emptyRow('No client connected.', 6);

    function renderClients(list) {
      const items = [];
      for (const p of list) {
        for (const c of Array.isArray(p.clients) ? p.clients : []) items.push({plc: p.id, c});
      }
      syncRows(clientsBody, clientRows, items, (it) => it.plc + '\n' + it.c.peer + '\n' + it.c.protocol,
        (it) => {
          const cells = clientCells();
          const link = el('a', {text: it.plc, attrs: {href: plcUrl(it.plc) + '/traffic'}});
          const tr = el('tr', {dataset: {plc: it.plc, peer: it.c.peer}}, el('th', {attrs: {scope: 'row'}}, link),
            ...CLIENT_FIELDS.map((f) => cells[f]));
          return {tr, cells};
        },
        (r, it) => showClient(r.cells, it.c), noClients);
    }

    function render(data) {
      const list = Array.isArray(data.plcs) ? data.plcs : [];
      const key = list.map((p) => p.id).join('\n');
      if (key !== order) {
        order = key;
        rows.clear();
        tbody.replaceChildren();
        for (const p of list) {
          const r = makeRow(p);
          rows.set(p.id, r);
          tbody.append(r.tr);
        }
        if (!list.length) {
          tbody.append(el('tr', {}, el('td', {text: 'No PLCs.', attrs: {colspan: 11}})));
        }
      }
      for (const p of list) update(rows.get(p.id), p);
      if (clientsBody) renderClients(list);
    }

    request('GET', '/api/v1/plcs')
      .then((data) => {
        render(data);
        live('/api/v1/events', {plcs: render});
      })
      .catch((e) => {
        setStatus('', '');
        say(e.message, 'error');
      });
  }

  // ---- Devices ------------------------------------------------------------------------------

  function devices() {
    const params = new URLSearchParams(location.search);
    const from = (params.get('from') || '').trim() || 'R0';
    const count = (params.get('count') || '').trim() || '20';
    const fromInput = byId('from');
    const countInput = byId('count');
    const table = byId('devices');
    const thead = table.querySelector('thead tr');
    const tbody = table.querySelector('tbody');
    fromInput.value = from;
    countInput.value = count;

    byId('range').addEventListener('submit', (ev) => {
      ev.preventDefault();
      const f = fromInput.value.trim();
      const n = countInput.value.trim();
      if (!f) {
        say('From device: give a device name such as R100, WM800, X17, D0 or M10', 'error');
        return;
      }
      if (!/^\d+$/.test(n) || Number(n) < 1 || Number(n) > 1000) {
        say('Count: expected 1 to 1000, got \'' + n + '\'', 'error');
        return;
      }
      location.assign(location.pathname + '?' + new URLSearchParams({from: f, count: n}).toString());
    });

    const devicePath = (name) => apiPlc(plc) + '/devices/' + encodeURIComponent(name);
    let bits = false;
    let names = [];
    const rows = new Map(); // name -> {input, valueCell, signed, hex, bits, words, current}

    function header(wide) {
      const cols = bits ? ['Device', 'Value'] : ['Device', 'Decimal', 'Signed', 'Hex', wide ? 'Bits (31 or 15 … 0)' : 'Bits (15 … 0)'];
      thead.replaceChildren(
        ...cols.map((c, i) => el('th', {text: c, className: i === 0 ? '' : i < 4 ? 'num' : '', attrs: {scope: 'col'}}))
      );
    }

    function render(data) {
      bits = data.bits === true;
      names = data.names.map(String);
      const words = Array.isArray(data.words) ? data.words : [];
      rows.clear();
      header(words.includes(2));
      const trs = names.map((name, i) => {
        const input = el('input', {
          className: 'value',
          dataset: {device: name},
          attrs: {type: 'text', inputmode: bits ? 'numeric' : 'text', autocomplete: 'off', spellcheck: 'false', 'aria-label': name + ' value'},
        });
        const valueCell = el('td', {className: 'num', dataset: {device: name}}, input);
        const r = {input, valueCell, words: words[i] === 2 ? 2 : 1, current: null};
        const tr = el('tr', {}, el('th', {className: 'device', text: name, attrs: {scope: 'row'}}), valueCell);
        if (!bits) {
          r.signed = el('td', {className: 'num mono'});
          r.hex = el('td', {className: 'num mono'});
          r.bits = el('td', {className: 'bits'});
          tr.append(r.signed, r.hex, r.bits);
        }
        rows.set(name, r);
        return tr;
      });
      tbody.replaceChildren(...trs);
      byId('devices-wrap').hidden = false;
      show(data);
    }

    function showOne(r, v) {
      r.current = v;
      r.valueCell.dataset.value = String(v);
      if (document.activeElement !== r.input) {
        r.input.value = String(v);
        r.input.classList.remove('edited');
      }
      if (!bits) {
        setText(r.signed, signedOf(v, r.words));
        setText(r.hex, hexOf(v, r.words));
        setText(r.bits, bitsOf(v, r.words));
      }
    }

    function show(data) {
      const ns = data.names || [];
      const vs = data.values || [];
      for (let i = 0; i < ns.length && i < vs.length; ++i) {
        const r = rows.get(String(ns[i]));
        if (r && typeof vs[i] === 'number') showOne(r, vs[i]);
      }
    }

    function onValues(data) {
      if (!Array.isArray(data.names) || data.names.join('\n') !== names.join('\n')) {
        // Other devices than the table's (a reload changed the PLC): rebuild it.
        if (Array.isArray(data.names) && Array.isArray(data.values)) render({...data, bits});
        return;
      }
      show(data);
    }

    async function write(input) {
      const name = input.dataset.device;
      const text = input.value.trim();
      const v = parseValue(text);
      if (v === null) {
        say(name + ': \'' + text + '\' is not a whole number (write 1234, -5 or 0x1F)', 'error');
        return;
      }
      input.setAttribute('aria-busy', 'true');
      try {
        const res = await request('PUT', devicePath(name), {values: [v]});
        const r = rows.get(name);
        const back = Array.isArray(res.values) ? res.values[0] : v;
        input.value = String(back);
        input.classList.remove('edited');
        if (r) showOne(r, back);
        say(name + ' = ' + back + (bits ? '' : ' (' + hexOf(back, r ? r.words : 1) + ')') + ': written', 'ok');
      } catch (e) {
        say(e.message, 'error');
      } finally {
        input.removeAttribute('aria-busy');
      }
    }

    function restore(input) {
      const r = rows.get(input.dataset.device);
      if (r && r.current !== null) input.value = String(r.current);
      input.classList.remove('edited');
    }

    editInPlace(tbody, write, restore);

    request('GET', devicePath(from) + '?count=' + encodeURIComponent(count))
      .then((data) => {
        render(data);
        const query = new URLSearchParams({device: from, count}).toString();
        live(apiPlc(plc) + '/events?' + query, {
          values: onValues,
          plcs: (d) => {
            const p = Array.isArray(d.plcs) ? d.plcs[0] : null;
            describePlc(p);
            if (p) setStatus('Live · ' + (p.running ? 'RUN' : 'STOP') + ' · scan ' + p.scans + ' · ' + fmtTime(p.time), 'live');
          },
        });
      })
      .catch((e) => {
        setStatus('', '');
        byId('devices-wrap').hidden = true;
        say(e.message, 'error');
      });
    loadPlcHeading();
  }

  // ---- Plant --------------------------------------------------------------------------------

  function plant() {
    const path = apiPlc(plc) + '/simulator';
    const tbody = document.querySelector('#channels tbody');
    const frozenButton = byId('frozen');
    const scaleInput = byId('time-scale');
    const stepInput = byId('step-count');
    const stepButton = byId('step');
    const showAll = byId('show-all');
    const simTime = byId('sim-time');
    const SHOWN = 8;
    const rows = [];
    let state = null;
    let writes = 0; // a poll begun before a write may not show the state from before it

    for (let c = 0; c < 32; ++c) {
      const temp = el('td', {className: 'num', dataset: {field: 'temperature'}});
      const progress = el('progress', {attrs: {max: 100, value: 0, 'aria-label': 'Channel ' + c + ' heater power'}});
      const powerText = el('span', {dataset: {field: 'power'}});
      const ambient = el('td', {className: 'num'});
      const buttons = {};
      const faults = el('div', {className: 'faults'});
      for (const [key, label] of FAULTS) {
        buttons[key] = el('button', {
          text: label,
          dataset: {channel: c, fault: key},
          attrs: {type: 'button', 'aria-pressed': 'false', title: 'Channel ' + c + ': ' + label},
        });
        faults.append(buttons[key]);
      }
      const tr = el('tr', {dataset: {channel: c}}, el('th', {className: 'num', text: c, attrs: {scope: 'row'}}), temp,
        el('td', {}, progress, powerText), ambient, el('td', {}, faults));
      tr.hidden = c >= SHOWN;
      rows.push({tr, temp, progress, powerText, ambient, buttons});
      tbody.append(tr);
    }

    function apply(s) {
      state = s;
      frozenButton.setAttribute('aria-pressed', s.frozen ? 'true' : 'false');
      if (document.activeElement !== scaleInput) scaleInput.value = String(s.time_scale);
      const pending = s.pending_steps ? ' · ' + s.pending_steps + ' scans queued' : '';
      setText(simTime, 'Simulated time ' + fmtNumber(s.simulated_s, 1) + ' s · time scale ' + fmtScale(s.time_scale) + ' · ' +
        (s.frozen ? 'frozen' : 'running') + pending);
      for (const ch of Array.isArray(s.channels) ? s.channels : []) {
        const r = rows[ch.channel];
        if (!r) continue;
        setText(r.temp, fmtNumber(ch.true_temperature_c, 1) + ' °C');
        const pct = typeof ch.heater_power === 'number' ? ch.heater_power * 100 : 0;
        r.progress.value = pct;
        setText(r.powerText, fmtNumber(pct, 0) + ' %');
        setText(r.ambient, fmtNumber(ch.ambient_c, 1) + ' °C');
        for (const [key] of FAULTS) {
          const on = !!(ch.faults && ch.faults[key]);
          r.buttons[key].setAttribute('aria-pressed', on ? 'true' : 'false');
        }
      }
    }

    const poll = poller(path, () => writes, apply, () => 'Updated every second');

    async function change(body, done) {
      ++writes;
      try {
        const s = await request('PUT', path, body);
        ++writes;
        apply(s);
        say(done, 'ok');
      } catch (e) {
        say(e.message, 'error');
      }
    }

    frozenButton.addEventListener('click', () => {
      const freeze = !(state && state.frozen);
      change({frozen: freeze}, freeze ? 'Frozen: no scans run until resumed or stepped' : 'Running');
    });
    byId('scale-form').addEventListener('submit', (ev) => {
      ev.preventDefault();
      const x = Number(scaleInput.value);
      if (!scaleInput.value.trim() || !Number.isFinite(x)) {
        say('Time scale: expected a number from 1 to 10000', 'error');
        return;
      }
      change({time_scale: x}, 'Time scale ' + fmtScale(x));
    });
    const stepLabel = () => {
      const n = Number(stepInput.value);
      setText(stepButton, 'Step ' + (Number.isInteger(n) && n > 0 ? n : 'N') + (n === 1 ? ' scan' : ' scans'));
    };
    stepInput.addEventListener('input', stepLabel);
    stepLabel();
    byId('step-form').addEventListener('submit', (ev) => {
      ev.preventDefault();
      const n = Number(stepInput.value);
      if (!/^\d+$/.test(stepInput.value.trim()) || n < 1 || n > 65535) {
        say('Step: expected a number of scans from 1 to 65535', 'error');
        return;
      }
      change({step: n}, 'Queued ' + n + (n === 1 ? ' scan' : ' scans'));
    });
    tbody.addEventListener('click', (ev) => {
      const b = ev.target instanceof Element ? ev.target.closest('button[data-fault]') : null;
      if (!b) return;
      const c = Number(b.dataset.channel);
      const key = b.dataset.fault;
      const on = b.getAttribute('aria-pressed') !== 'true';
      const label = (FAULTS.find(([k]) => k === key) || [key, key])[1];
      change({channels: [{channel: c, faults: {[key]: on}}]}, 'Channel ' + c + ': ' + label + (on ? ' on' : ' off'));
    });
    showAll.addEventListener('click', () => {
      const all = showAll.getAttribute('aria-pressed') !== 'true';
      showAll.setAttribute('aria-pressed', all ? 'true' : 'false');
      rows.forEach((r, c) => {
        r.tr.hidden = !all && c >= SHOWN;
      });
    });

    const comm = commFaults();
    request('GET', path)
      .then((s) => {
        apply(s);
        setStatus('Updated every second', 'live');
        setInterval(() => {
          poll();
          comm.poll();
        }, 1000);
      })
      .catch((e) => {
        setStatus('', '');
        say(e.message, 'error');
      });
    loadPlcHeading();
  }

  // The plant page's communication faults: a button a fault, lit while it is on; the form's
  // delay, exception code and scope; Clear all. Every change PUTs the whole set the page wants
  // (the state last read, the one fault switched, the scope of the form); Clear all DELETEs.
  // Returns {poll}, called with the page's refresh.
  function commFaults() {
    const path = apiPlc(plc) + '/comm-faults';
    const section = byId('comm');
    const box = byId('comm-buttons');
    const delayInput = byId('comm-delay');
    const exceptionInput = byId('comm-exception');
    const fromInput = byId('comm-from');
    const countInput = byId('comm-count');
    const inputs = [delayInput, exceptionInput, fromInput, countInput];
    const summary = byId('comm-summary');
    const faultsText = summary.querySelector('[data-field="faults"]');
    const scopeText = summary.querySelector('[data-field="scope"]');
    const figures = byId('comm-figures');
    const buttons = new Map();
    let state = null;
    let writes = 0; // a poll begun before a write may show the state from before it
    let busy = false;
    let gone = false;

    for (const fault of COMM_FAULTS) {
      const b = el('button', {dataset: {commFault: fault.key}, attrs: {type: 'button', 'aria-pressed': 'false', title: fault.title}});
      buttons.set(fault.key, b);
      box.append(b);
    }

    // The form as values: null where a field says nothing that makes sense.
    function form() {
      const d = delayInput.value.trim();
      let delay = null;
      let m = /^(\d+)$/.exec(d);
      if (m) delay = Number(m[1]);
      m = /^(\d+)\s*-\s*(\d+)$/.exec(d);
      if (m) delay = [Number(m[1]), Number(m[2])];
      const x = parseValue(exceptionInput.value);
      const c = countInput.value.trim();
      return {
        delay,
        exception: x !== null && x >= 1 && x <= 255 ? x : null,
        from: fromInput.value.trim(),
        count: c === '' ? undefined : /^\d+$/.test(c) ? Number(c) : null,
      };
    }

    function labels() {
      const f = form();
      for (const fault of COMM_FAULTS) setText(buttons.get(fault.key), fault.label(f));
    }

    // A field keeps what is typed in it (until a write succeeds); else it shows the server's.
    function showField(input, text) {
      if (document.activeElement !== input && !input.classList.contains('edited')) input.value = text;
    }

    function show(s) {
      state = s;
      for (const fault of COMM_FAULTS) buttons.get(fault.key).setAttribute('aria-pressed', fault.lit(s) ? 'true' : 'false');
      if (delayOn(s)) showField(delayInput, fmtDelay(s.delay_ms));
      if (exceptionOn(s)) showField(exceptionInput, String(s.exception));
      showField(fromInput, s.from ? String(s.from) : '');
      showField(countInput, s.from ? String(s.count) : '');
      labels();
      const sum = s.summary || {};
      const list = Array.isArray(sum.faults) ? sum.faults : [];
      setText(faultsText, list.length ? list.join(', ') : 'none');
      setText(scopeText, sum.scope || '—');
      summary.classList.toggle('on', !!s.active);
      const n = s.figures || {};
      setText(figures, 'So far: ' + COMM_FIGURES.map((k) => k + ' ' + (n[k] !== undefined ? n[k] : '—')).join(', '));
    }

    async function poll() {
      if (busy || gone) return;
      busy = true;
      const seen = writes;
      try {
        const s = await request('GET', path);
        if (seen === writes) show(s);
      } catch (e) {
        if (e.status === 404) {
          // No communication faults here: no panel.
          gone = true;
          section.hidden = true;
        }
      } finally {
        busy = false;
      }
    }

    // The body that keeps the faults on now, with the form's scope; null (and said why) when
    // the form's scope is not a number.
    function body(f) {
      const b = {};
      for (const k of COMM_FIELDS) {
        if (state && state[k] !== undefined && state[k] !== null) b[k] = state[k];
      }
      delete b.from;
      delete b.count;
      if (f.count === null) {
        say('Count: expected a number of devices from 1 to 65535', 'error');
        return null;
      }
      if (f.from) {
        b.from = f.from;
        if (f.count !== undefined) b.count = f.count;
      }
      return b;
    }

    async function change(method, b) {
      ++writes;
      try {
        const s = await request(method, path, b);
        ++writes;
        for (const input of inputs) input.classList.remove('edited');
        show(s);
        const list = s.summary && Array.isArray(s.summary.faults) ? s.summary.faults : [];
        say('Communication faults: ' + (list.length ? list.join(', ') + ' (' + (s.summary.scope || '') + ')' : 'none'), 'ok');
      } catch (e) {
        say(e.message, 'error');
      }
    }

    const badDelay = 'Delay: expected ms from 0 to 60000, or min-max such as 100-300';
    const badException = 'Exception: expected a code from 1 to 255 (4, or 0x0B)';

    box.addEventListener('click', (ev) => {
      const button = ev.target instanceof Element ? ev.target.closest('button[data-comm-fault]') : null;
      if (!button) return;
      const fault = COMM_FAULTS.find((x) => x.key === button.dataset.commFault);
      const on = button.getAttribute('aria-pressed') !== 'true';
      const f = form();
      const why = !on ? '' : fault.key === 'delay' && f.delay === null ? badDelay :
        fault.key === 'exception' && f.exception === null ? badException : '';
      if (why) {
        say(why, 'error');
        return;
      }
      const b = body(f);
      if (!b) return;
      fault.set(b, f, on);
      change('PUT', b);
    });
    byId('comm-form').addEventListener('submit', (ev) => {
      ev.preventDefault();
      const f = form();
      const b = body(f);
      if (!b) return;
      const delay = state !== null && delayOn(state);
      const exception = state !== null && exceptionOn(state);
      const why = delay && f.delay === null ? badDelay : exception && f.exception === null ? badException : '';
      if (why) {
        say(why, 'error');
        return;
      }
      if (delay) b.delay_ms = f.delay;
      if (exception) b.exception = f.exception;
      change('PUT', b);
    });
    byId('comm-clear').addEventListener('click', () => change('DELETE'));
    for (const input of inputs) {
      input.addEventListener('input', () => {
        input.classList.add('edited');
        labels();
      });
    }

    labels();
    poll();
    return {poll};
  }

  // ---- Traffic ------------------------------------------------------------------------------

  // Names of the function codes and exception codes, as a master's manual calls them.
  const MODBUS_FUNCTIONS = {
    0x01: 'read coils', 0x02: 'read discrete inputs', 0x03: 'read holding registers',
    0x04: 'read input registers', 0x05: 'write single coil', 0x06: 'write single register',
    0x07: 'read exception status', 0x08: 'diagnostics', 0x0B: 'get comm event counter',
    0x0C: 'get comm event log', 0x0F: 'write multiple coils', 0x10: 'write multiple registers',
    0x11: 'report server ID', 0x14: 'read file record', 0x15: 'write file record',
    0x16: 'mask write register', 0x17: 'read/write multiple registers', 0x18: 'read FIFO queue',
    0x2B: 'read device identification',
  };
  const MODBUS_EXCEPTIONS = {
    0x01: 'illegal function', 0x02: 'illegal data address', 0x03: 'illegal data value',
    0x04: 'server device failure', 0x05: 'acknowledge', 0x06: 'server device busy',
    0x08: 'memory parity error', 0x0A: 'gateway path unavailable', 0x0B: 'gateway target failed to respond',
  };
  const FATEK_COMMANDS = {
    0x40: 'read system status', 0x41: 'RUN/STOP', 0x42: 'single discrete control',
    0x43: 'read enable/disable flags', 0x44: 'read discretes', 0x45: 'write discretes',
    0x46: 'read registers', 0x47: 'write registers', 0x48: 'mixed read', 0x49: 'mixed write',
    0x4E: 'loop-back test', 0x53: 'read detailed system status',
  };
  // FATEK error codes are characters: '2' (32h), '4' (34h), 'A' (41h).
  const FATEK_ERRORS = {0x32: 'illegal value', 0x34: 'illegal format', 0x41: 'illegal address'};

  // "03h" -> its name in `names`, or ''.
  function codeName(code, names) {
    const m = /^([0-9A-F]{2})h$/i.exec(code || '');
    return m ? names[parseInt(m[1], 16)] || '' : '';
  }

  function traffic() {
    const path = apiPlc(plc) + '/traffic';
    const clientsBody = document.querySelector('#clients tbody');
    const exchangesBody = document.querySelector('#exchanges tbody');
    const pauseButton = byId('pause');
    const clientRows = new Map();
    const noClients = emptyRow('No client connected.', 5);
    let paused = false;
    let pauses = 0; // an answer asked for before a pause or a resume is not shown in the list
    let shownKey = null;

    function showClients(list) {
      syncRows(clientsBody, clientRows, list, (c) => c.peer + '\n' + c.protocol,
        (c) => {
          const cells = clientCells();
          return {tr: el('tr', {dataset: {peer: c.peer}}, ...CLIENT_FIELDS.map((f) => cells[f])), cells};
        },
        (r, c) => showClient(r.cells, c), noClients);
    }

    function exchangeRow(x) {
      const protocol = String(x.protocol || '');
      const modbus = protocol.startsWith('modbus');
      const fatek = protocol.startsWith('fatek');
      const fn = String(x.function || '');
      const err = String(x.error || '');
      const unit = x.unit === undefined || x.unit === null ? '' : String(x.unit);
      const fnName = codeName(fn, modbus ? MODBUS_FUNCTIONS : fatek ? FATEK_COMMANDS : {});
      const tr = el('tr', {
        className: err ? 'refused' : '',
        dataset: {at: x.at || '', client: x.client || '', protocol, unit, function: fn, error: err},
      });
      const at = el('td', {className: 'mono', text: fmtClock(x.at), dataset: {field: 'at'}, attrs: {title: x.at || ''}});
      const fnCell = el('td', {dataset: {field: 'function'}}, el('span', {className: 'code', text: fn || '—'}));
      if (fnName) fnCell.append(' ', el('span', {className: 'hint', text: fnName}));
      const devices = el('td', {className: x.devices ? 'mono' : 'hint', text: x.devices || '—', dataset: {field: 'devices'}});
      const errCell = el('td', {dataset: {field: 'error'}});
      if (err) {
        const errName = codeName(err, modbus ? MODBUS_EXCEPTIONS : fatek ? FATEK_ERRORS : {});
        errCell.append(el('span', {className: 'badge refused', text: err, attrs: {title: 'Refused: ' + (modbus ? 'exception ' : 'error ') + err}}));
        if (errName) errCell.append(' ', el('span', {className: 'hint', text: errName}));
      }
      tr.append(at, el('td', {className: 'mono', text: x.client || '—', dataset: {field: 'client'}}),
        el('td', {text: protocol || '—', dataset: {field: 'protocol'}}),
        el('td', {className: 'num', text: unit || '—', dataset: {field: 'unit'}}), fnCell, devices, errCell);
      return tr;
    }

    // The server lists them oldest first; the page, newest first.
    function showExchanges(list) {
      const key = JSON.stringify(list);
      if (key === shownKey) return;
      shownKey = key;
      const trs = list.slice().reverse().map(exchangeRow);
      exchangesBody.replaceChildren(...(trs.length ? trs : [emptyRow('No request yet.', 7)]));
    }

    function showStatus() {
      if (paused) {
        setStatus('Paused: the list of requests is kept as it is (Resume to follow it again)', 'paused');
      } else {
        setStatus('Updated every second', 'live');
      }
    }

    let polling = false;
    let again = false; // resumed while a poll was out: poll once more when it is back
    async function poll() {
      if (polling) return;
      polling = true;
      again = false;
      const asked = pauses;
      const list = !paused;
      try {
        // Paused, only the clients are wanted: one request, not a hundred.
        const data = await request('GET', path + (list ? '?count=100' : '?count=1'));
        showClients(Array.isArray(data.clients) ? data.clients : []);
        if (list && asked === pauses) showExchanges(Array.isArray(data.exchanges) ? data.exchanges : []);
        showStatus();
      } catch (e) {
        setStatus(e.message, 'down');
      } finally {
        polling = false;
        if (again) poll();
      }
    }

    pauseButton.addEventListener('click', () => {
      paused = !paused;
      ++pauses;
      pauseButton.setAttribute('aria-pressed', paused ? 'true' : 'false');
      setText(pauseButton, paused ? 'Resume' : 'Pause');
      showStatus();
      if (!paused) {
        // The list follows again at once (an answer still out was asked for while paused).
        again = polling;
        poll();
      }
    });

    poll().then(() => setInterval(poll, 1000));
    loadPlcHeading();
  }

  // ---- Loops --------------------------------------------------------------------------------

  const SVG_NS = 'http://www.w3.org/2000/svg';
  const TREND_S = 600; // a trend's span: the last 10 simulated minutes
  const GOOD_FLAGS = new Set(['in zone']); // lamps lit green, not as a warning
  const SERIES = [['pv', 'PV'], ['sv', 'SV'], ['output', 'Output %']];

  // svg('polyline', {class: 'pv', points: '...'}): an SVG element, its attributes set as given.
  function svg(tag, attrs = {}, ...children) {
    const e = document.createElementNS(SVG_NS, tag);
    for (const [k, v] of Object.entries(attrs)) e.setAttribute(k, String(v));
    for (const c of children) e.append(c);
    return e;
  }

  // Digits after the point for values counted in `scale` units: 0.1 -> 1, 0.25 -> 2, 1 -> 0.
  function decimalsOf(scale) {
    if (typeof scale !== 'number' || !Number.isFinite(scale) || scale <= 0 || Number.isInteger(scale)) return 0;
    const m = /\.(\d+)$/.exec(String(scale));
    return Math.min(6, m ? m[1].length : Math.ceil(-Math.log10(scale)));
  }

  // "123.4", "-5", ".5", "12,5" -> a number; anything else -> null.
  function parseDecimal(text) {
    const s = text.trim().replace(',', '.');
    return /^[+-]?(\d+\.?\d*|\.\d+)$/.test(s) ? Number(s) : null;
  }

  // A tick step of 1, 2 or 5 times a power of ten, about `rough`.
  function niceStep(rough) {
    const p = Math.pow(10, Math.floor(Math.log10(rough)));
    const f = rough / p;
    return (f <= 1 ? 1 : f <= 2 ? 2 : f <= 5 ? 5 : 10) * p;
  }

  // The trend's drawing: viewBox units, the plot's area inside it.
  const TW = 360;
  const TH = 150;
  const PLOT = {x0: 40, x1: 322, y0: 8, y1: 128};

  function makeTrend(loop) {
    const grid = svg('g', {class: 'grid'});
    const lines = {};
    for (const [key] of SERIES) {
      lines[key] = svg('polyline', {class: 'series ' + key, fill: 'none', 'stroke-width': 1.6,
        'stroke-linejoin': 'round', 'data-series': key, 'data-points': 0, points: ''});
    }
    const box = svg('svg', {class: 'trend', viewBox: '0 0 ' + TW + ' ' + TH, role: 'img',
      'aria-label': loop.name + ': trend of the last 10 simulated minutes'}, grid, lines.pv, lines.sv, lines.output);
    const legend = el('p', {className: 'legend'});
    for (const [key, label] of SERIES) {
      const item = el('span', {className: 'key ' + key, text: label, dataset: {series: key}});
      if (key === 'output') item.hidden = !(loop.output_full > 0);
      legend.append(item);
    }
    return {box, grid, lines, legend};
  }

  // Draws samples [{t, pv, sv, out}] ending at `now` (simulated seconds) into trend `tr`.
  function drawTrend(tr, samples, now, digits, unit) {
    const {x0, x1, y0, y1} = PLOT;
    const xOf = (t) => x0 + (x1 - x0) * (t - (now - TREND_S)) / TREND_S;
    const values = [];
    for (const s of samples) {
      if (s.pv !== null) values.push(s.pv);
      values.push(s.sv);
    }
    let lo = values.length ? Math.min(...values) : 0;
    let hi = values.length ? Math.max(...values) : 1;
    const span = hi - lo > 1e-9 ? hi - lo : Math.max(1, Math.abs(hi) * 0.1);
    const step = niceStep(span / 3);
    lo = Math.floor((lo - span * 0.05) / step) * step;
    hi = Math.ceil((hi + span * 0.05) / step) * step;
    const yOf = (v) => y1 - (y1 - y0) * (v - lo) / (hi - lo);
    const yPct = (p) => y1 - (y1 - y0) * Math.min(100, Math.max(0, p)) / 100;
    const tickDigits = Math.max(0, Math.min(digits, Math.ceil(-Math.log10(step))));
    const kids = [svg('rect', {class: 'plot', x: x0, y: y0, width: x1 - x0, height: y1 - y0})];
    for (let v = lo, i = 0; v <= hi + step / 2 && i < 12; v += step, ++i) {
      const y = yOf(v);
      kids.push(svg('line', {x1: x0, x2: x1, y1: y, y2: y}));
      const label = svg('text', {x: x0 - 4, y: y + 3.5, 'text-anchor': 'end'});
      label.textContent = v.toFixed(tickDigits);
      kids.push(label);
    }
    if (unit) {
      const u = svg('text', {x: 3, y: y0 + 3.5, 'text-anchor': 'start', class: 'unit'});
      u.textContent = unit;
      kids.push(u);
    }
    if (!tr.legend.querySelector('.output').hidden) {
      for (const p of [0, 50, 100]) {
        const label = svg('text', {x: x1 + 4, y: yPct(p) + 3.5, 'text-anchor': 'start', class: 'pct'});
        label.textContent = p + ' %';
        kids.push(label);
      }
    }
    for (const [m, anchor] of [[10, 'start'], [5, 'middle'], [0, 'end']]) {
      const label = svg('text', {x: xOf(now - m * 60), y: TH - 6, 'text-anchor': anchor});
      label.textContent = m ? '−' + m + ' min' : 'now';
      kids.push(label);
    }
    tr.grid.replaceChildren(...kids);
    const line = (key, pick, y) => {
      const pts = [];
      for (const s of samples) {
        const v = pick(s);
        if (v !== null) pts.push(xOf(s.t).toFixed(1) + ',' + y(v).toFixed(1));
      }
      tr.lines[key].setAttribute('points', pts.join(' '));
      tr.lines[key].setAttribute('data-points', String(pts.length));
    };
    line('pv', (s) => s.pv, yOf);
    line('sv', (s) => s.sv, yOf);
    line('output', (s) => s.out, yPct);
  }

  function loops() {
    const box = byId('loops');
    const none = byId('no-loops');
    const flagPath = (device) => apiPlc(plc) + '/devices/' + encodeURIComponent(device);
    let cards = [];
    let shape = null; // what the cards were built for: the loops' names and devices
    let lastT = null;
    let writes = 0; // an answer asked for before a write finished may show the value before it

    // What makes the faceplates: a change (a reload) rebuilds them.
    const shapeOf = (list) => JSON.stringify(list.map((l) => [l.name, l.unit, l.scale, l.output_full,
      l.pv && l.pv.device, l.sv && l.sv.device, l.output && l.output.device,
      (l.parameters || []).map((p) => [p.name, p.device, p.unit]),
      (l.alarms || []).map((a) => [a.name, a.device, a.bit]),
      [l.manual, l.tuning].map((f) => f && [f.device, f.bit]), l.true_temperature_c !== undefined]));

    // A value field: the set point (engineering units) or a parameter (raw).
    function field(card, device, kind, label) {
      const input = el('input', {
        className: 'value',
        dataset: {device, kind},
        attrs: {type: 'text', inputmode: kind === 'sv' ? 'decimal' : 'text', autocomplete: 'off', spellcheck: 'false',
          'aria-label': label + ' (' + device + ')', title: device},
      });
      card.inputs.set(input, {kind, current: ''});
      return input;
    }

    // A reading's box: its label above, then its value and what follows it.
    function reading(label, key, ...rest) {
      return el('div', {className: 'reading ' + key, dataset: {field: key}}, el('span', {className: 'label', text: label}), ...rest);
    }

    function makeCard(l, index) {
      const card = {loop: l, samples: [], inputs: new Map(), lamps: []};
      const digits = decimalsOf(l.scale);
      card.digits = digits;
      const title = el('h2', {text: l.name, attrs: {id: 'loop-' + index + '-name'}});
      card.mode = el('span', {className: 'badge mode', dataset: {field: 'mode'}});
      const switches = el('div', {className: 'switches'});
      if (l.manual) {
        card.manual = el('button', {text: 'Manual', dataset: {switch: 'manual', device: l.manual.device, bit: l.manual.bit},
          attrs: {type: 'button', 'aria-pressed': 'false', title: l.manual.device + ' bit ' + l.manual.bit + ': manual output'}});
        switches.append(card.manual);
      }
      if (l.tuning) {
        card.tuning = el('button', {text: 'Start auto-tuning', dataset: {switch: 'tuning', device: l.tuning.device, bit: l.tuning.bit},
          attrs: {type: 'button', 'aria-pressed': 'false', title: l.tuning.device + ' bit ' + l.tuning.bit + ': auto-tuning'}});
        switches.append(card.tuning);
      }
      const head = el('div', {className: 'loop-head'}, el('div', {}, title, ' ', card.mode), switches);

      const unit = l.unit ? ' ' + l.unit : '';
      card.pv = el('span', {className: 'big', dataset: {field: 'pv-value'}});
      card.pvDevice = el('span', {className: 'device'});
      card.sv = field(card, l.sv.device, 'sv', 'Set point');
      const readings = el('div', {className: 'readings'},
        reading('PV', 'pv', card.pv, el('span', {className: 'unit', text: unit}), card.pvDevice),
        reading('SV', 'sv', card.sv, el('span', {className: 'unit', text: unit}), el('span', {className: 'device', text: l.sv.device})));
      if (l.true_temperature_c !== undefined) {
        card.plantTemp = el('span', {className: 'big', dataset: {field: 'true-temperature'}});
        const r = reading('Plant', 'true', card.plantTemp, el('span', {className: 'unit', text: ' °C'}),
          el('span', {className: 'device', text: 'channel ' + l.channel}));
        r.title = 'The process\'s true temperature, before the sensor and its faults';
        readings.append(r);
      }

      card.outBar = el('progress', {attrs: {max: 100, value: 0, 'aria-label': l.name + ' output'}});
      card.outText = el('span', {className: 'out-text', dataset: {field: 'output'}});
      card.outRaw = el('span', {className: 'device'});
      card.outBar.hidden = !(l.output_full > 0);
      const output = el('div', {className: 'output'}, el('span', {className: 'label', text: 'Output'}), card.outBar, card.outText, card.outRaw);

      const lamps = el('div', {className: 'lamps'});
      for (const a of l.alarms || []) {
        const lamp = el('span', {className: 'lamp' + (GOOD_FLAGS.has(a.name) ? ' good' : ''), text: a.name,
          dataset: {alarm: a.name, on: 'false'}});
        card.lamps.push(lamp);
        lamps.append(lamp);
      }

      card.trend = makeTrend(l);

      const params = el('div', {className: 'params'});
      for (const p of l.parameters || []) {
        params.append(el('label', {className: 'param'}, el('span', {className: 'name', text: p.name}),
          field(card, p.device, 'parameter', p.name), el('span', {className: 'unit', text: p.unit || ''})));
      }

      card.article = el('article', {className: 'loop', dataset: {loop: index}, attrs: {'aria-labelledby': 'loop-' + index + '-name'}},
        head, readings, output, lamps, card.trend.box, card.trend.legend, params);
      return card;
    }

    const shown = (v, digits) => (typeof v === 'number' && Number.isFinite(v) ? v.toFixed(digits) : '—');

    function showInput(card, input, text) {
      const f = card.inputs.get(input);
      f.current = text;
      if (document.activeElement !== input && !input.hasAttribute('aria-busy')) {
        input.value = text;
        input.classList.remove('edited');
      }
    }

    function cardOf(input) {
      const article = input.closest('article[data-loop]');
      return cards[Number(article.dataset.loop)];
    }

    function showSwitch(button, flag, onText, offText) {
      if (!button || !flag) return;
      button.setAttribute('aria-pressed', flag.on ? 'true' : 'false');
      setText(button, flag.on ? onText : offText);
    }

    function update(card, l) {
      card.loop = l;
      const d = card.digits;
      setText(card.pv, l.pv ? shown(l.pv.value, d) : '—');
      setText(card.pvDevice, l.pv ? l.pv.device + ' = ' + l.pv.raw : 'no reading');
      showInput(card, card.sv, shown(l.sv.value, d));
      if (card.plantTemp) setText(card.plantTemp, shown(l.true_temperature_c, 1));
      const pct = l.output && typeof l.output.percent === 'number' ? l.output.percent : null;
      if (pct !== null) {
        card.outBar.value = Math.min(100, Math.max(0, pct));
        setText(card.outText, pct.toFixed(1) + ' %');
        setText(card.outRaw, l.output.device + ' = ' + l.output.raw);
      } else {
        setText(card.outText, l.output ? String(l.output.raw) : '—');
        setText(card.outRaw, l.output ? l.output.device : '');
      }
      (l.alarms || []).forEach((a, i) => {
        const lamp = card.lamps[i];
        if (!lamp) return;
        lamp.classList.toggle('on', !!a.on);
        lamp.dataset.on = a.on ? 'true' : 'false';
        lamp.title = a.device + ' bit ' + a.bit + ': ' + (a.on ? 'on' : 'off');
      });
      (l.parameters || []).forEach((p) => {
        for (const [input, f] of card.inputs) {
          if (f.kind === 'parameter' && input.dataset.device === p.device) showInput(card, input, String(p.value));
        }
      });
      showSwitch(card.manual, l.manual, 'Manual', 'Manual');
      showSwitch(card.tuning, l.tuning, 'Auto-tuning…', 'Start auto-tuning');
      if (card.tuning) card.tuning.disabled = !!(l.tuning && l.tuning.on);
      const mode = l.tuning && l.tuning.on ? 'tuning' : l.manual && l.manual.on ? 'manual' : 'auto';
      setText(card.mode, mode);
      card.mode.className = 'badge mode ' + mode;
    }

    function sample(card, l, t) {
      const s = {t, pv: l.pv ? l.pv.value : null, sv: l.sv.value,
        out: l.output && typeof l.output.percent === 'number' ? l.output.percent : null};
      const last = card.samples[card.samples.length - 1];
      if (last && last.t === t) {
        card.samples[card.samples.length - 1] = s; // frozen: the same instant, the values as now
      } else {
        card.samples.push(s);
      }
      while (card.samples.length && card.samples[0].t < t - TREND_S) card.samples.shift();
      drawTrend(card.trend, card.samples, t, card.digits, card.loop.unit);
    }

    function apply(data) {
      const list = Array.isArray(data.loops) ? data.loops : [];
      const t = typeof data.simulated_s === 'number' ? data.simulated_s : performance.now() / 1000;
      const s = shapeOf(list);
      if (s !== shape) {
        // Other loops (a reload changed the program): new faceplates, their trends filled with
        // what the PLC kept of the last 10 simulated minutes.
        shape = s;
        cards = list.map(makeCard);
        box.replaceChildren(...cards.map((c) => c.article));
        fillTrends(cards);
      } else if (lastT !== null && t < lastT) {
        // Simulated time went back (a reload): the trends start over.
        for (const c of cards) c.samples = [];
      }
      lastT = t;
      none.hidden = list.length > 0;
      list.forEach((l, i) => {
        update(cards[i], l);
        sample(cards[i], l, t);
      });
    }

    // The samples the PLC kept ([t, pv, sv, output] a simulated second) before this page's
    // first poll; those of the page's own polls come after them.
    async function fillTrends(built) {
      let data;
      try {
        data = await request('GET', apiPlc(plc) + '/loops/history');
      } catch (e) {
        return; // the trends then start with the page
      }
      if (cards !== built || !Array.isArray(data.loops)) return;
      data.loops.forEach((h, i) => {
        const card = built[i];
        if (!card || h.name !== card.loop.name || !Array.isArray(h.samples)) return;
        const first = card.samples.length ? card.samples[0].t : Infinity;
        const kept = h.samples.filter((x) => x[0] < first)
          .map((x) => ({t: x[0], pv: x[1], sv: x[2], out: x[3]}));
        card.samples = kept.concat(card.samples);
        const last = card.samples[card.samples.length - 1];
        if (last) drawTrend(card.trend, card.samples, last.t, card.digits, card.loop.unit);
      });
    }

    const poll = poller(apiPlc(plc) + '/loops', () => writes, apply,
      (data) => 'Updated every second · simulated time ' + fmtNumber(data.simulated_s, 1) + ' s');

    async function write(input) {
      const card = cardOf(input);
      const f = card.inputs.get(input);
      const name = input.dataset.device;
      const text = input.value.trim();
      let raw;
      if (f.kind === 'sv') {
        const v = parseDecimal(text);
        const scale = card.loop.scale > 0 ? card.loop.scale : 1;
        raw = v === null ? null : Math.round(v / scale);
        if (raw === null || !Number.isSafeInteger(raw)) {
          say(name + ': \'' + text + '\' is not a number (write the set point in ' + (card.loop.unit || 'counts') + ', e.g. 150.5)', 'error');
          return;
        }
      } else {
        raw = parseValue(text);
        if (raw === null) {
          say(name + ': \'' + text + '\' is not a whole number (write 1234, -5 or 0x1F)', 'error');
          return;
        }
      }
      input.setAttribute('aria-busy', 'true');
      ++writes;
      try {
        const res = await request('PUT', flagPath(name), {values: [raw]});
        ++writes;
        const back = signed16(Array.isArray(res.values) ? res.values[0] : raw);
        const shownBack = f.kind === 'sv' ? (back * card.loop.scale).toFixed(card.digits) : String(back);
        f.current = shownBack;
        input.value = shownBack;
        input.classList.remove('edited');
        say(name + ' = ' + back + (f.kind === 'sv' && card.loop.unit ? ' (' + shownBack + ' ' + card.loop.unit + ')' : '') +
          ': written', 'ok');
      } catch (e) {
        say(e.message, 'error');
      } finally {
        input.removeAttribute('aria-busy');
      }
    }

    function restore(input) {
      const f = cardOf(input).inputs.get(input);
      input.value = f.current;
      input.classList.remove('edited');
    }

    // Sets or clears a flag's bit: a bit device is written 0/1, a word read, changed and written.
    async function setFlag(flag, on, done) {
      ++writes;
      try {
        const now = await request('GET', flagPath(flag.device));
        const v = Number(now.values[0]);
        const mask = 1 << flag.bit;
        const next = now.bits ? (on ? 1 : 0) : (on ? v | mask : v & ~mask) & 0xFFFF;
        await request('PUT', flagPath(flag.device), {values: [next]});
        ++writes;
        say(done, 'ok');
      } catch (e) {
        say(e.message, 'error');
      }
      poll();
    }

    box.addEventListener('click', (ev) => {
      const b = ev.target instanceof Element ? ev.target.closest('button[data-switch]') : null;
      if (!b) return;
      const card = cards[Number(b.closest('article[data-loop]').dataset.loop)];
      const l = card.loop;
      if (b.dataset.switch === 'tuning' && l.tuning) {
        setFlag(l.tuning, true, l.name + ': auto-tuning started (' + l.tuning.device + ' bit ' + l.tuning.bit + ')');
      } else if (b.dataset.switch === 'manual' && l.manual) {
        const on = !l.manual.on;
        setFlag(l.manual, on, l.name + ': ' + (on ? 'manual' : 'automatic') + ' (' + l.manual.device + ' bit ' + l.manual.bit + ' ' + (on ? 'on' : 'off') + ')');
      }
    });
    editInPlace(box, write, restore);

    poll().then(() => setInterval(poll, 1000));
    loadPlcHeading();
  }

  // ---- Start --------------------------------------------------------------------------------

  initNav();
  initToken();
  if (page === 'overview') {
    overview();
  } else if (page === 'devices') {
    devices();
  } else if (page === 'plant') {
    plant();
  } else if (page === 'traffic') {
    traffic();
  } else if (page === 'loops') {
    loops();
  } else if (plc !== null) {
    loadPlcHeading();
  }
})();
