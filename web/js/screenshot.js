// The 3D view as a PNG download: "shapectl-yumi_bar-2026-11-24T04-30-12.png". The renderer keeps
// its drawing buffer (view3d.js), so the canvas holds the last frame; render once more anyway
// so the picture is the current state.
export function screenshotName(sceneName, date = new Date()) {
  const stem = (sceneName ?? 'view').replace(/\.json$/, '');
  return `shapectl-${stem}-${date.toISOString().slice(0, 19).replaceAll(':', '-')}.png`;
}

export function saveScreenshot(view, sceneName) {
  view.render();
  const link = document.createElement('a');
  link.download = screenshotName(sceneName);
  link.href = view.renderer.domElement.toDataURL('image/png');
  link.click();
}
