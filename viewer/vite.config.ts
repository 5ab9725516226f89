import { cpSync, readdirSync } from 'node:fs';
import { join } from 'node:path';
import { defineConfig, type Plugin } from 'vitest/config';

/** The npm package of MediaPipe Hands: its script, models and WebAssembly. */
const MEDIAPIPE = 'node_modules/@mediapipe/hands';

/**
 * Copies MediaPipe Hands' runtime files into dist/mediapipe, where the Camera button loads
 * them from (its script is not an ES module, and its models are fetched by name at run time),
 * so the page needs no network. Only what the solution loads: not its README or typings.
 */
function mediapipeFiles(): Plugin {
  return {
    name: 'dqhand-mediapipe-files',
    apply: 'build',
    writeBundle(options) {
      const out = join(options.dir ?? 'dist', 'mediapipe');
      for (const file of readdirSync(MEDIAPIPE).filter((f) => /\.(js|wasm|data|tflite|binarypb)$/.test(f))) {
        cpSync(join(MEDIAPIPE, file), join(out, file));
      }
    },
  };
}

// The page is served by `dqhand demo` from dist/; relative asset paths keep it portable.
export default defineConfig({
  base: './',
  plugins: [mediapipeFiles()],
  // The npm package's sources the page shares (its look.ts) import three: this one, not a copy
  // (the package's folder has no node_modules of its own when the viewer is built).
  resolve: { dedupe: ['three'] },
  build: { outDir: 'dist', emptyOutDir: true, chunkSizeWarningLimit: 1024 },
  test: { include: ['tests/**/*.test.ts'], testTimeout: 120_000, hookTimeout: 120_000, fileParallelism: false },
});
