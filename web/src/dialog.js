// A modal confirmation (<dialog id="confirm">) for every action that moves the robot or is recorded:
// nothing is sent before the operator confirms. Optional text fields (who decides, a reason).

const NAME_KEY = 'scanplan.operator-name';

export function operatorName() {
  try {
    return localStorage.getItem(NAME_KEY) || '';
  } catch {
    return '';
  }
}

function rememberName(name) {
  try {
    localStorage.setItem(NAME_KEY, name);
  } catch {
    /* storage disabled: ask again next time */
  }
}

let busy = null;

/**
 * @param {{title: string, body: string, confirm: string, danger?: boolean,
 *          reason?: boolean}} opts
 * @returns {Promise<null | {by: string, reason: string}>} null when cancelled
 */
export function confirmAction({ title, body, confirm, danger = false, reason = false }) {
  const dlg = document.getElementById('confirm');
  if (busy) busy(null); // a newer question replaces an open one
  document.getElementById('confirm-title').textContent = title;
  document.getElementById('confirm-body').textContent = body;
  const ok = document.getElementById('confirm-ok');
  ok.textContent = confirm;
  ok.classList.toggle('danger', danger);
  const by = document.getElementById('confirm-by');
  by.value = operatorName();
  const reasonRow = document.getElementById('confirm-reason-row');
  const reasonInput = document.getElementById('confirm-reason');
  reasonRow.hidden = !reason;
  reasonInput.value = '';
  return new Promise((resolve) => {
    const done = (value) => {
      busy = null;
      ok.onclick = null;
      document.getElementById('confirm-cancel').onclick = null;
      dlg.oncancel = null;
      if (dlg.open) dlg.close();
      resolve(value);
    };
    busy = done;
    ok.onclick = (e) => {
      e.preventDefault();
      const name = by.value.trim().slice(0, 100);
      rememberName(name);
      done({ by: name, reason: reasonInput.value.trim().slice(0, 500) });
    };
    document.getElementById('confirm-cancel').onclick = (e) => {
      e.preventDefault();
      done(null);
    };
    dlg.oncancel = (e) => {
      e.preventDefault();
      done(null);
    };
    dlg.showModal();
    ok.focus();
  });
}
