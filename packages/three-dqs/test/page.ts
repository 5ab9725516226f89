// One page for both: `?bench` the speed page (window.bench), else the conformance page
// (window.conformance). The title says when either is ready.
const page = new URLSearchParams(location.search).has('bench') ? { bench: (await import('./bench')).bench } : { conformance: (await import('./conformance')).conformance };
Object.assign(window, page);
document.title = 'ready';
export {};
