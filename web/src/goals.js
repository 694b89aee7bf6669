// The operator's own scan point: a click on the top view marks a spot; "Propose" sends it to
// POST /api/v1/goals {x, y, robot, by}. The server checks it against the movable region and answers with a
// custom candidate (F, gains, drive) to approve like the planner's, or 400 with the reason, shown here.
import { sendJson } from './api.js';
import { operatorName } from './dialog.js';

const f1 = (v) => v.toFixed(1);

export class GoalPicker {
  /**
   * @param {{bar: HTMLElement, where: HTMLElement, propose: HTMLButtonElement, clear: HTMLButtonElement, msg: HTMLElement}} els
   * @param {{onPending: (p: {x, y}|null) => void, onProposed: (candidate: object) => void,
   *          robotFor?: () => string|null}} handlers  robotFor: which robot the point is for (null: the server's choice)
   */
  constructor(els, { onPending, onProposed, robotFor = () => null }) {
    this.els = els;
    this.onPending = onPending;
    this.robotFor = robotFor;
    this.onProposed = onProposed;
    this.point = null;
    this.operator = false;
    this.busy = false;
    els.propose.addEventListener('click', () => this.propose());
    els.clear.addEventListener('click', () => this.set(null));
  }

  setRole(operator) {
    this.operator = operator;
    this.render();
  }

  set(point) {
    this.point = point;
    this.els.msg.textContent = '';
    this.els.msg.classList.remove('error');
    this.onPending(point);
    this.render();
  }

  render() {
    const { bar, where, propose } = this.els;
    bar.hidden = !this.point;
    if (!this.point) return;
    const robot = this.robotFor();
    where.textContent = `(${f1(this.point.x)}, ${f1(this.point.y)})${robot ? ` for ${robot}` : ''}`;
    propose.hidden = !this.operator;
    propose.disabled = this.busy;
  }

  async propose() {
    if (!this.point || this.busy) return;
    const { msg } = this.els;
    this.busy = true;
    msg.textContent = 'checking with the server…';
    msg.classList.remove('error');
    this.render();
    try {
      const by = operatorName();
      const robot = this.robotFor();
      const c = await sendJson('/api/v1/goals', { x: this.point.x, y: this.point.y, ...(robot ? { robot } : {}), ...(by ? { by } : {}) });
      this.busy = false;
      this.set(null);
      this.onProposed(c);
    } catch (e) {
      this.busy = false;
      msg.textContent = `not possible: ${e.detail || e.message}`;
      msg.classList.add('error');
      this.render();
    }
  }
}
