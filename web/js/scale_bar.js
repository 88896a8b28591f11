// A scale bar over the 3D view: a bar of a round length (1, 2 or 5 × 10^k m) as long as that
// length appears at the orbit centre's depth, and the floor grid's cell size. Updated when the
// camera moves or the view resizes.
const MIN_BAR_PX = 60;
const GRID_CELL_M = 0.1;  // view3d.js' GridHelper: 2 m in 20 cells

// "5 cm", "2 mm", "1 m".
export function lengthLabel(metres) {
  if (metres >= 1) return `${+metres.toPrecision(3)} m`;
  if (metres >= 0.01) return `${+(100 * metres).toPrecision(3)} cm`;
  return `${+(1000 * metres).toPrecision(3)} mm`;
}

// The smallest 1, 2 or 5 × 10^k m that spans at least `minPx` at `pxPerMetre`.
function roundLength(pxPerMetre, minPx) {
  const want = minPx / pxPerMetre, decade = 10 ** Math.floor(Math.log10(want));
  return [1, 2, 5, 10].map((m) => m * decade).find((m) => m >= want);
}

export class ScaleBar {
  // `element`: the overlay (a bar <i> and a label <span> are put in it); `view`: the View3D.
  constructor(element, view) {
    this.view = view;
    this.bar = document.createElement('i');
    this.label = document.createElement('span');
    this.grid = document.createElement('span');
    this.grid.className = 'grid-label';
    this.grid.textContent = `grid ${lengthLabel(GRID_CELL_M)}`;
    element.append(this.bar, this.label, this.grid);
    this.metres = 0;  // the bar's length, m
    this.pixels = 0;  // its length on screen, CSS px
    view.orbit.addEventListener('change', () => this.update());
    new ResizeObserver(() => this.update()).observe(view.container);
    this.update();
  }

  update() {
    const camera = this.view.camera, height = this.view.container.clientHeight;
    const depth = camera.position.distanceTo(this.view.orbit.target);
    if (!(height > 0 && depth > 0)) return;
    const pxPerMetre = height / (2 * depth * Math.tan(camera.fov * Math.PI / 360));
    this.metres = roundLength(pxPerMetre, MIN_BAR_PX);
    this.pixels = this.metres * pxPerMetre;
    this.bar.style.width = `${this.pixels.toFixed(1)}px`;
    this.label.textContent = lengthLabel(this.metres);
  }
}
