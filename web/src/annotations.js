// Annotations: marks on the map (victim, hazard, blocked, note) placed by clicking a point in the 3-D
// view. GET/POST /api/v1/annotations with {"kind","x","y","z","text"} -> 201 {id, kind, x, y, z,
// text, author, created_at}; others' marks arrive as {"type":"annotation", ...same fields} events.
// A server without the endpoint (404) shows that annotations are unavailable; nothing breaks.
import { ApiError, getJson, sendJson } from './api.js';
import { confirmAction, operatorName } from './dialog.js';

export const KINDS = ['victim', 'hazard', 'blocked', 'note'];
const f1 = (v) => (Number.isFinite(v) ? v.toFixed(1) : '?');

function el(tag, className, text) {
  const e = document.createElement(tag);
  if (className) e.className = className;
  if (text !== undefined) e.textContent = text;
  return e;
}

export class AnnotationsPanel {
  /**
   * @param {{list: HTMLElement, status: HTMLElement, form: HTMLFormElement, count: HTMLElement}} els
   * @param {{onChange: (list: object[]) => void, onFocus: (a: object) => void}} handlers
   */
  constructor(els, { onChange, onFocus }) {
    this.els = els;
    this.onChange = onChange;
    this.onFocus = onFocus;
    this.items = new Map(); // id -> annotation
    this.state = 'unknown'; // unknown | available | unavailable | error
    this.reason = '';
    this.operator = false;
    this.placing = null; // {x, y, z} while the form is open
    const f = els.form;
    f.addEventListener('submit', (e) => {
      e.preventDefault();
      this._save();
    });
    f.querySelector('[data-act=cancel]').addEventListener('click', () => this.closeForm());
  }

  get available() {
    return this.state === 'available';
  }

  get list() {
    return [...this.items.values()].sort((a, b) => a.id - b.id);
  }

  setRole(operator) {
    this.operator = operator;
    this.render();
  }

  /** (Re)loads the list; tells whether the server has annotations at all. */
  async load() {
    try {
      const answer = await getJson('/api/v1/annotations');
      const list = Array.isArray(answer) ? answer : Array.isArray(answer?.annotations) ? answer.annotations : null;
      if (!list) throw new ApiError('/api/v1/annotations: unexpected answer');
      this.items.clear();
      for (const a of list) if (valid(a)) this.items.set(a.id, a);
      this.state = 'available';
      this.reason = '';
    } catch (e) {
      if (e instanceof ApiError && (e.status === 404 || e.status === 405)) {
        this.state = 'unavailable';
        this.reason = 'this server has no annotations (GET /api/v1/annotations answers 404)';
      } else if (!(e instanceof ApiError && e.network)) {
        this.state = 'error';
        this.reason = e.detail || e.message;
      }
    }
    this.render();
    this.onChange(this.list);
  }

  /** An `annotation` event. */
  onEvent(e) {
    if (!valid(e)) return;
    // type and at are destructured only to leave them out of the stored mark.
    // eslint-disable-next-line no-unused-vars
    const { type, at, ...a } = e;
    this.items.set(a.id, a);
    if (this.state !== 'available') this.state = 'available';
    this.render();
    this.onChange(this.list);
  }

  /** annotation_deleted: the mark was withdrawn (the server keeps it on record). */
  onDeleted(e) {
    if (!this.items.delete(e.id)) return;
    this.render();
    this.onChange(this.list);
  }

  async remove(a) {
    const ok = await confirmAction({
      title: `Withdraw the ${a.kind} mark?`,
      body: `“${a.text || a.kind}” at (${f1(a.x)}, ${f1(a.y)}) disappears from every screen; the session keeps it on record with your name.`,
      confirm: 'Withdraw',
      danger: true,
    });
    if (!ok) return;
    try {
      await sendJson(`/api/v1/annotations/${a.id}`, ok.by ? { by: ok.by } : {}, { method: 'DELETE' });
      this.items.delete(a.id);
      this.render();
      this.onChange(this.list);
    } catch (e) {
      this.els.status.textContent = `not withdrawn: ${e.detail || e.message}`;
    }
  }

  /** Opens the form for a mark at a picked map point. */
  openForm(point, screen) {
    const f = this.els.form;
    this.placing = { x: point.x, y: point.y, z: point.z };
    f.querySelector('.where').textContent = `at (${f1(point.x)}, ${f1(point.y)}, ${f1(point.z)})`;
    f.querySelector('.msg').textContent = '';
    f.querySelector('[name=text]').value = '';
    f.hidden = false;
    const parent = f.offsetParent || f.parentElement;
    const pr = parent.getBoundingClientRect();
    const x = Math.min(Math.max(8, screen.x - pr.left + 12), pr.width - f.offsetWidth - 8);
    const y = Math.min(Math.max(8, screen.y - pr.top + 12), pr.height - f.offsetHeight - 8);
    f.style.left = `${x}px`;
    f.style.top = `${y}px`;
    f.querySelector('[name=text]').focus();
  }

  closeForm() {
    this.els.form.hidden = true;
    this.placing = null;
  }

  async _save() {
    const f = this.els.form;
    const msg = f.querySelector('.msg');
    if (!this.placing) return;
    const kind = f.querySelector('[name=kind]').value;
    const text = f.querySelector('[name=text]').value.trim();
    if (!KINDS.includes(kind)) {
      msg.textContent = 'choose what this mark is';
      return;
    }
    if (kind === 'note' && !text) {
      msg.textContent = 'a note needs a text';
      return;
    }
    if (text.length > 1000) {
      msg.textContent = `the text is ${text.length} characters; at most 1000`;
      return;
    }
    const save = f.querySelector('[type=submit]');
    save.disabled = true;
    msg.textContent = 'saving…';
    try {
      const by = operatorName();
      const a = await sendJson('/api/v1/annotations', { kind, ...this.placing, text, ...(by ? { by } : {}) });
      if (valid(a)) this.items.set(a.id, a);
      this.state = 'available';
      this.closeForm();
      this.render();
      this.onChange(this.list);
    } catch (e) {
      if (e instanceof ApiError && e.status === 404) {
        this.state = 'unavailable';
        this.reason = 'this server has no annotations (POST /api/v1/annotations answers 404)';
        this.closeForm();
        this.render();
      } else {
        msg.textContent = `not saved: ${e.detail || e.message}`;
      }
    } finally {
      save.disabled = false;
    }
  }

  render() {
    const { list, status, count } = this.els;
    document.body.dataset.annotations = this.state;
    count.textContent = this.state === 'available' ? String(this.items.size) : '–';
    list.replaceChildren();
    if (this.state === 'unavailable' || this.state === 'error') {
      status.textContent = this.state === 'unavailable' ? `Annotations unavailable: ${this.reason}.` : `Annotations could not be loaded: ${this.reason}`;
      status.className = 'annot-status unavailable';
      return;
    }
    if (this.state === 'unknown') {
      status.textContent = 'loading annotations…';
      status.className = 'annot-status';
      return;
    }
    status.textContent = this.operator ? 'To add one, choose “Annotate” above the 3-D view and click a point of the map.' : '';
    status.className = 'annot-status';
    const items = this.list.reverse();
    if (!items.length) list.append(el('li', 'muted', 'no annotations yet'));
    for (const a of items) {
      const li = el('li', `annot kind-${a.kind}`);
      li.dataset.id = String(a.id);
      const head = el('div', 'annot-head');
      head.append(el('span', `kind kind-${a.kind}`, a.kind), el('span', 'where', `(${f1(a.x)}, ${f1(a.y)}, ${f1(a.z)})`));
      if (this.operator) {
        const del = el('button', 'annot-delete', '✕');
        del.type = 'button';
        del.title = 'withdraw this mark';
        del.addEventListener('click', (ev) => {
          ev.stopPropagation();
          this.remove(a);
        });
        head.append(del);
      }
      li.append(head);
      if (a.text) li.append(el('div', 'annot-text', a.text));
      const when = a.created_at ? new Date(a.created_at) : null;
      const meta = [a.author, when && !Number.isNaN(when.getTime()) ? when.toLocaleTimeString('en-GB', { hour12: false }) : a.created_at].filter(Boolean).join(' · ');
      if (meta) li.append(el('div', 'annot-meta', meta));
      li.addEventListener('click', () => this.onFocus(a));
      list.append(li);
    }
  }
}

function valid(a) {
  return a && Number.isFinite(a.id) && typeof a.kind === 'string' && Number.isFinite(a.x) && Number.isFinite(a.y) && Number.isFinite(a.z);
}
