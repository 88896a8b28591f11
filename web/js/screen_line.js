// A polyline drawn a few screen pixels wide and over everything (three.js' Line2): the
// centre-line lies inside the bar, and a 1-px WebGL line is easy to miss. Each update builds a
// new geometry: three.js never grows a line buffer in place ("Buffer size too small" when a
// longer stroke reuses it), and a sketch is at most a few hundred points.
import { Line2 } from 'three/addons/lines/Line2.js';
import { LineGeometry } from 'three/addons/lines/LineGeometry.js';
import { LineMaterial } from 'three/addons/lines/LineMaterial.js';

export class ScreenLine {
  constructor(color, widthPixels, renderOrder) {
    this.material = new LineMaterial({ color, linewidth: widthPixels, depthTest: false, depthWrite: false, transparent: true });
    this.line = new Line2(new LineGeometry(), this.material);
    this.line.frustumCulled = false;
    this.line.renderOrder = renderOrder;
    this.line.visible = false;
    this.pointCount = 0;
  }

  get object() { return this.line; }

  // `points`: [x, y, z] arrays or Vector3s; fewer than 2 hides the line.
  setPoints(points) {
    this.pointCount = points.length;
    this.line.visible = points.length > 1;
    if (!this.line.visible) return;
    const flat = new Float32Array(3 * points.length);
    points.forEach((p, k) => {
      if (Array.isArray(p)) flat.set(p, 3 * k);
      else flat.set([p.x, p.y, p.z], 3 * k);
    });
    this.line.geometry.dispose();
    this.line.geometry = new LineGeometry().setPositions(flat);
  }

  // The drawing buffer's size in pixels (LineMaterial needs it for the width).
  setResolution(width, height) { this.material.resolution.set(width, height); }
}
