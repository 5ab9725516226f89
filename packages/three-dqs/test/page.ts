// One page for three: `?bench` the speed page (window.bench), `?figure` the side-by-side
// pictures (window.figure), else the conformance page (window.conformance). The title says
// when it is ready.
const query = new URLSearchParams(location.search);
const page = query.has('bench')
  ? { bench: (await import('./bench')).bench }
  : query.has('figure')
    ? { figure: (await import('./figure')).figure }
    : { conformance: (await import('./conformance')).conformance };
Object.assign(window, page);
document.title = 'ready';
export {};
