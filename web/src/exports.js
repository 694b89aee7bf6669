// Exports for other teams (GET /api/v1/export/...): the registered map as PLY or LAS, the scan
// poses as CSV, the annotations as GeoJSON, all in the map frame; and the printable mission
// report (GET /api/v1/report.html). The API wants the token in a
// header, which a plain link cannot send: the file is fetched, then saved from memory.
import { apiFetch } from './api.js';

const MB = 1024 * 1024;

function sizeText(bytes) {
  return bytes >= MB ? `${(bytes / MB).toFixed(1)} MB` : `${Math.max(1, Math.round(bytes / 1024))} kB`;
}

export class ExportMenu {
  /**
   * @param {HTMLSelectElement} select its options' values are the export names; "" is the prompt
   * @param {HTMLElement} message where progress and the outcome are shown
   */
  constructor(select, message) {
    this.select = select;
    this.message = message;
    this.busy = false;
    select.addEventListener('change', () => {
      const name = select.value;
      select.value = '';
      if (name) this.save(name);
    });
  }

  async save(name) {
    if (this.busy) return;
    this.busy = true;
    this.select.disabled = true;
    this.show(`preparing ${name}…`, false);
    try {
      // A whole map is tens to hundreds of megabytes: give the server and the link time.
      const path = name === 'report.html' ? '/api/v1/report.html' : `/api/v1/export/${name}`;
      const res = await apiFetch(path, { timeoutMs: 300000 });
      const blob = await res.blob();
      const url = URL.createObjectURL(blob);
      const a = document.createElement('a');
      a.href = url;
      a.download = `scanplan-${name}`;
      document.body.append(a);
      a.click();
      a.remove();
      // The download has its own copy once started.
      setTimeout(() => URL.revokeObjectURL(url), 60000);
      this.show(`saved scanplan-${name} (${sizeText(blob.size)}, map frame)`, false);
    } catch (e) {
      this.show(e.code === 'no_map' ? 'nothing to export yet: no scan is in the map' : `export failed: ${e.message}`, true);
    } finally {
      this.busy = false;
      this.select.disabled = false;
    }
  }

  show(text, error) {
    this.message.textContent = text;
    this.message.classList.toggle('error', error);
    this.message.dataset.state = error ? 'error' : text.startsWith('saved') ? 'saved' : 'busy';
  }
}
