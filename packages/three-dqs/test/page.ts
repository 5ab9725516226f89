// One page for four: `?bench` the speed page (window.bench), `?figure` the side-by-side
// pictures (window.figure, window.handFigure), `?webgpu` the conformance page through WebGPURenderer
// (`?webgpu&webgl`: its WebGL 2 fallback), else the conformance page through WebGLRenderer
// (window.conformance). The title says when it is ready.
const query = new URLSearchParams(location.search);
async function page(): Promise<object> {
  if (query.has('bench')) return { bench: (await import('./bench')).bench };
  if (query.has('figure')) {
    const { figure, handFigure } = await import('./figure');
    return { figure, handFigure };
  }
  const { conformance, shadowConformance, sharedBuildConformance } = await import('./conformance');
  if (query.has('webgpu')) {
    const backend = await (await import('./webgpu_readback')).webgpu(query.has('webgl'));
    return {
      conformance: async (names: string[]) => ({
        backend: backend.backend,
        ...(await conformance(backend, names)),
        shadows: await shadowConformance(backend.shadows),
        sharedBuild: await sharedBuildConformance(backend.twoMeshes),
      }),
    };
  }
  const { webgl } = await import('./webgl_readback');
  return { conformance: (names: string[]) => conformance(webgl, names) };
}
Object.assign(window, await page());
document.title = 'ready';
export {};
