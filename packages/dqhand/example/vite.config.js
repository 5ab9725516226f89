import { defineConfig } from 'vite';

export default defineConfig({
  // Relative paths: the built page works from any folder of any static host.
  base: './',
  // The package finds its .wasm files beside its own modules (new URL(…, import.meta.url)),
  // which the dev server's pre-bundling would move away from them.
  optimizeDeps: { exclude: ['dqhand'] },
  build: { target: 'es2022' },
});
