// ESLint flat config for the operator page: lints web/src only (`npm run lint`).
// The page is a set of ES modules in the browser; map_chunks_worker.js is a classic Web Worker
// (bundled as an IIFE, loads the Draco decoder with importScripts), so it gets worker globals
// and no DOM.
import js from '@eslint/js';
import globals from 'globals';

const worker = 'src/map_chunks_worker.js';

export default [
  { ignores: ['dist/', 'node_modules/', 'build.mjs', 'eslint.config.js'] },
  {
    files: ['src/**/*.js'],
    ...js.configs.recommended,
    linterOptions: { reportUnusedDisableDirectives: 'error' },
    rules: {
      ...js.configs.recommended.rules,
      'no-unused-vars': ['error', { args: 'after-used' }],
      eqeqeq: ['error', 'smart'],
    },
  },
  {
    files: ['src/**/*.js'],
    ignores: [worker],
    languageOptions: { ecmaVersion: 2022, sourceType: 'module', globals: { ...globals.browser } },
  },
  {
    files: [worker],
    languageOptions: { ecmaVersion: 2022, sourceType: 'script', globals: { ...globals.worker } },
  },
];
