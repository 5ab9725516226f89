import { defineConfig } from 'vite';

// The conformance and speed page (index.html; ?bench for the speed), built for a static
// server: relative paths.
export default defineConfig({ root: 'test', base: './', build: { target: 'es2022', emptyOutDir: true, chunkSizeWarningLimit: 1024 } });
