// umbra playground — the example scenes of the list (and the bench scenes embed.sh adds).
'use strict';

// ---- examples ----
const sun = (extra) => Object.assign({ type: 'directional', direction: [-0.5, -1, -0.3], intensity: 3 }, extra || {});
function filterScene(filter) {
  return {
    width: 512, height: 384,
    camera: { position: [4, 3, 5], target: [0, 0.7, 0], fov_y: 40 },
    environment: { background: [0.55, 0.6, 0.68], ambient: { intensity: 0.3 } },
    materials: { floor: { base_color: [0.75, 0.75, 0.72], roughness: 0.9 }, red: { base_color: [0.8, 0.25, 0.2], roughness: 0.5 } },
    objects: [
      { shape: 'plane', size: [12, 12], material: 'floor' },
      { shape: 'box', size: [1, 1.6, 1], material: 'red', transform: { translation: [-0.8, 0.8, 0], rotation: [0, 0.38, 0, 0.925] } },
      { shape: 'sphere', radius: 0.6, material: 'floor', transform: { translation: [1, 1.6, 0.6] } },
      { shape: 'cylinder', radius: 0.08, height: 1.0, transform: { translation: [1, 0.5, 0.6] } },
    ],
    lights: [sun({ angular_diameter: 3 })],
    shadows: { filter, resolution: 2048 },
  };
}
function cascadesScene() {
  const objects = [{ shape: 'plane', size: [300, 300], material: 'ground' }];
  for (let k = 0; k < 24; k++) {
    const z = -3 - k * 5, h = 2 + (k * 7) % 5;
    objects.push({ shape: 'box', size: [1.6, h, 1.6], material: 'wall', transform: { translation: [k % 2 ? 3 : -3, h / 2, z] } });
  }
  return {
    width: 640, height: 360,
    camera: { position: [0, 1.7, 6], target: [0, 1.2, -20], fov_y: 60, near: 0.1, far: 200 },
    environment: { background: [0.55, 0.7, 0.9], ambient: { sky: [0.55, 0.7, 0.9], ground: [0.3, 0.28, 0.25], intensity: 0.4 } },
    materials: { ground: { base_color: [0.45, 0.42, 0.38], roughness: 0.95 }, wall: { base_color: [0.8, 0.76, 0.7] } },
    objects,
    lights: [sun({ direction: [-0.6, -1, -0.4], shadow: { filter: 'pcf', directional: { mode: 'cascades', cascades: 4 } } })],
  };
}
function lightsScene() {
  return {
    width: 512, height: 384,
    camera: { position: [6, 5, 7], target: [0, 0.5, 0], fov_y: 45 },
    environment: { background: [0.05, 0.05, 0.06], ambient: { intensity: 0.15 } },
    materials: { floor: { base_color: [0.6, 0.6, 0.6], roughness: 0.9 }, gold: { base_color: [1, 0.78, 0.34], roughness: 0.3, metallic: 1 } },
    objects: [
      { shape: 'plane', size: [12, 12], material: 'floor' },
      { shape: 'box', size: [0.8, 1.4, 0.8], transform: { translation: [-1.2, 0.7, -0.5] } },
      { shape: 'cylinder', radius: 0.4, height: 1.2, material: 'gold', transform: { translation: [1, 0.6, 0.4] } },
    ],
    lights: [
      { type: 'spot', position: [0, 4.5, 2], direction: [0, -1, -0.45], color: [1, 0.85, 0.7], intensity: 60, outer_angle: 40, inner_angle: 25, radius: 0.1 },
      { type: 'point', position: [-2.5, 2.5, 2], color: [0.4, 0.6, 1], intensity: 25, radius: 0.05 },
    ],
    shadows: { filter: 'pcss' },
  };
}
// A small OBJ (a stepped tower) as an inline model: the thumbnail preset frames it and puts a
// shadow catcher under it; the background is transparent, so the shadow is in alpha.
function towerObj() {
  const v = [], f = [];
  const box = (x0, y0, z0, x1, y1, z1) => {
    const b = v.length / 3 + 1;
    for (let k = 0; k < 8; k++) v.push(k & 1 ? x1 : x0, k & 2 ? y1 : y0, k & 4 ? z1 : z0);
    [[0, 2, 3, 1], [4, 5, 7, 6], [0, 1, 5, 4], [2, 6, 7, 3], [0, 4, 6, 2], [1, 3, 7, 5]]
      .forEach((q) => f.push('f ' + q.map((n) => n + b).join(' ')));
  };
  box(-1, 0, -1, 1, 0.6, 1); box(-0.7, 0.6, -0.7, 0.7, 1.4, 0.7); box(-0.35, 1.4, -0.35, 0.35, 2.6, 0.35);
  let s = '';
  for (let k = 0; k < v.length; k += 3) s += 'v ' + v.slice(k, k + 3).join(' ') + '\n';
  return s + f.join('\n') + '\n';
}
function catcherScene() {
  return {
    preset: 'thumbnail', width: 384, height: 384,
    output: { transparent: true },
    objects: [{ shape: 'model', format: 'obj', data: btoa(towerObj()), material: { base_color: [0.3, 0.55, 0.85] } }],
  };
}
function errorScene() {
  const s = filterScene('pcf');
  s.lights[0].direction = [0, 0, 0];
  return s;
}
const EXAMPLES = [];
FILTERS.forEach((f) => EXAMPLES.push(['Filter: ' + f, () => filterScene(f)]));
EXAMPLES.push(['Cascades: a street at dusk', cascadesScene]);
EXAMPLES.push(['Spot and point lights', lightsScene]);
EXAMPLES.push(['Model on a shadow catcher, transparent', catcherScene]);
EXAMPLES.push(['Thumbnail preset (sphere)', () => ({ preset: 'thumbnail', objects: [{ shape: 'sphere', segments: 96 }] })]);
Object.keys(window.UMBRA_BENCH || {}).sort().forEach((k) => EXAMPLES.push(['Bench: ' + k, () => window.UMBRA_BENCH[k]]));
EXAMPLES.push(['An error (zero light direction)', errorScene]);
