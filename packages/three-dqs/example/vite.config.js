import { defineConfig } from 'vite';

// Relative paths: the built page works from any folder of any static host.
export default defineConfig({ base: './', build: { target: 'es2022', chunkSizeWarningLimit: 1024 } });
