// tests/schema/corpus.js — scene documents for schema.test.js, each [name, expected verdict,
// document, Accept header (optional)]. "accept": umbrad answers 200; "reject": umbrad answers
// 400 and api/scene.schema.json must refuse it too; "server": a rule the schema cannot state
// (umbrad's 400 while the schema accepts; its description lists them). Documents are tiny (8x8,
// MSAA 1) so that the accepted ones render quickly.
'use strict';

const base = () => ({
  width: 8, height: 8,
  camera: { position: [4, 3, 4], target: [0, 0, 0] },
  objects: [{ shape: 'sphere' }],
  lights: [{ type: 'directional', direction: [-0.5, -1, -0.3] }],
  output: { msaa: 1 },
});
// base() with f applied to it (f may mutate its argument).
const doc = (f) => { const d = base(); if (f) f(d); return d; };
const light0 = (extra) => doc((d) => Object.assign(d.lights[0], extra));
const spot = (extra) => doc((d) => { d.lights = [Object.assign({ type: 'spot', position: [0, 3, 0], direction: [0, -1, 0] }, extra)]; });
const point = (extra) => doc((d) => { d.lights = [Object.assign({ type: 'point', position: [0, 3, 0] }, extra)]; });
const out = (extra) => doc((d) => Object.assign(d.output, extra));
const cam = (c) => doc((d) => { d.camera = c; });
const ortho = { type: 'orthographic', position: [4, 3, 4], target: [0, 0, 0], height: 3 };
const preset = (extra) => Object.assign({ preset: 'thumbnail', width: 8, height: 8, output: { msaa: 1 },
  objects: [{ shape: 'box' }] }, extra);
const ground = (extra) => doc((d) => d.objects.push(Object.assign({ shape: 'plane', placement: 'ground' }, extra)));
const contactOn = { contact: { enabled: true } };

module.exports = [
  // ---- accepted ----
  ['base scene', 'accept', doc()],
  ['fit camera with direction and margin', 'accept', cam({ fit: 'objects', direction: [-1, -1, -1], margin: 0.1 })],
  ['fit camera with fov_y and up', 'accept', cam({ fit: 'scene', fov_y: 30, up: [0, 1, 0] })],
  ['perspective camera with fov_y, near, far, exposure', 'accept', cam({ type: 'perspective', position: [4, 3, 4], target: [0, 0, 0], fov_y: 40, near: 0.1, far: 50, exposure: 1 })],
  ['orthographic camera with height', 'accept', cam(ortho)],
  ['views under an orthographic camera: a view with height only', 'accept', doc((d) => { d.camera = ortho; d.views = [{ height: 5 }, { position: [0, 5, 5] }]; })],
  ['views under an orthographic camera: a perspective view with fov_y', 'accept', doc((d) => { d.camera = ortho; d.views = [{ type: 'perspective', fov_y: 50 }]; })],
  ['views: an orthographic view under a perspective camera', 'accept', doc((d) => { d.views = [{ type: 'orthographic', height: 4 }, { fov_y: 60 }]; })],
  ['views under an orthographic camera: an orthographic view takes its height', 'accept', doc((d) => { d.camera = ortho; d.views = [{ type: 'orthographic', position: [0, 4, 4] }]; })],
  ['views without a root camera', 'accept', doc((d) => { delete d.camera; d.views = [{ position: [4, 3, 4], target: [0, 0, 0] }, { fit: 'objects' }]; })],
  ['turntable', 'accept', doc((d) => { delete d.camera; d.turntable = { frames: 2, elevation: 30 }; })],
  ['debug shadow with debug_light', 'accept', out({ debug: 'shadow', debug_light: 0 })],
  ['debug shadow without debug_light', 'accept', out({ debug: 'shadow' })],
  ['debug cascades', 'accept', out({ debug: 'cascades' })],
  ['directional light with shadow.directional', 'accept', light0({ shadow: { directional: { mode: 'cascades', cascades: 2 } } })],
  ['spot light with a pcf shadow', 'accept', spot({ shadow: { filter: 'pcf', pcf_radius: 2 } })],
  ['point light with radius and pcss', 'accept', point({ radius: 0.2, shadow: { filter: 'pcss' } })],
  ['contact shadows on a shadowed light', 'accept', light0({ shadow: contactOn })],
  ['contact settings on a light whose shadows are off, contact not enabled (a warning)', 'accept', light0({ shadow: { enabled: false, contact: { distance: 0.1 } } })],
  ['a light enabling its shadows and contact under root shadows off', 'accept', doc((d) => { d.shadows = { enabled: false }; d.lights[0].shadow = { enabled: true, contact: { enabled: true } }; })],
  ['root shadows false, a light with shadow true', 'accept', doc((d) => { d.shadows = false; d.lights[0].shadow = true; })],
  ['light shadow false', 'accept', light0({ shadow: false })],
  ['root shadows with contact and directional settings', 'accept', doc((d) => { d.shadows = { resolution: 512, contact: { enabled: true }, directional: { mode: 'fit' } }; })],
  ['ground-placed plane with margin', 'accept', ground({ margin: 2 })],
  ['ground-placed shadow catcher', 'accept', ground({ material: { shadow_catcher: true } })],
  ['plane with size and transform', 'accept', doc((d) => d.objects.push({ shape: 'plane', size: [5, 5], transform: { translation: [0, -1, 0] } }))],
  ['box, cylinder and an inline mesh', 'accept', doc((d) => d.objects.push({ shape: 'box', size: [1, 2, 1] }, { shape: 'cylinder', radius: 0.5, height: 1 },
    { shape: 'mesh', positions: [0, 0, 0, 1, 0, 0, 0, 1, 0] }))],
  ['named material', 'accept', doc((d) => { d.materials = { red: { base_color: [1, 0, 0], roughness: 0.4 } }; d.objects[0].material = 'red'; })],
  ['environment background and ambient', 'accept', doc((d) => { d.environment = { background: [0, 0, 0, 0], ambient: { sky: [1, 1, 1], intensity: 0.2 } }; })],
  ['extras and x- members', 'accept', doc((d) => { d.extras = { a: 1 }; d['x-note'] = 'hi'; d.camera['x-id'] = 3; })],
  ['format exr with aovs', 'accept', out({ format: 'exr', aovs: ['depth', 'shadow'] })],
  ['format webp', 'accept', out({ format: 'webp', transparent: true })],
  ['format webp with quality', 'accept', out({ format: 'webp', quality: 80 })],
  ['format avif', 'accept', out({ format: 'avif', transparent: true })],
  ['format avif with quality', 'accept', out({ format: 'avif', quality: 70 })],
  // Without output.format the Accept header chooses: the schema takes the document, which is
  // valid for the answer these name (the 4th element: the request's Accept).
  ['quality without format, Accept: image/webp', 'accept', out({ quality: 80 }), 'image/webp'],
  ['quality without format, Accept: image/avif', 'accept', out({ quality: 60 }), 'image/avif'],
  ['aovs without format, Accept: image/x-exr', 'accept', out({ aovs: ['normal'] }), 'image/x-exr'],
  ['png bit_depth 16, png_level 9, tonemap aces', 'accept', out({ bit_depth: 16, png_level: 9, tonemap: 'aces' })],
  ['preset', 'accept', preset()],
  ['preset with "shadows": null (RFC 7396: drops the preset\'s)', 'accept', preset({ shadows: null })],
  ['preset with "lights": null and "environment": null', 'accept', preset({ lights: null, environment: null })],
  ['preset with "output": {"transparent": true} and a width', 'accept', preset({ width: 16, output: { transparent: true, msaa: 1 } })],
  ['preset with its own lights', 'accept', preset({ lights: [{ type: 'point', position: [0, 3, 0] }] })],
  ['preset with a camera position', 'accept', preset({ camera: { position: [3, 3, 3], target: [0, 0, 0] } })],

  // ---- rejected, and the schema can say so ----
  ['camera position with fit', 'reject', cam({ fit: 'objects', position: [1, 2, 3] })],
  ['camera target with fit', 'reject', cam({ fit: 'scene', target: [0, 0, 0] })],
  ['height on a perspective camera (type absent)', 'reject', cam({ position: [4, 3, 4], target: [0, 0, 0], height: 2 })],
  ['height on a perspective camera', 'reject', cam({ type: 'perspective', position: [4, 3, 4], target: [0, 0, 0], height: 2 })],
  ['fov_y on an orthographic camera', 'reject', cam(Object.assign({ fov_y: 30 }, ortho))],
  ['views under an orthographic camera: fov_y on a view of its type', 'reject', doc((d) => { d.camera = ortho; d.views = [{ fov_y: 30 }]; })],
  ['views under a perspective camera: height on a view of its type', 'reject', doc((d) => { d.views = [{ height: 3 }]; })],
  ['views under a perspective camera: an orthographic view without height', 'reject', doc((d) => { d.views = [{ type: 'orthographic' }]; })],
  ['orthographic camera without height', 'reject', cam({ type: 'orthographic', position: [4, 3, 4], target: [0, 0, 0] })],
  ['debug_light without debug', 'reject', out({ debug_light: 0 })],
  ['debug_light with debug normals', 'reject', out({ debug: 'normals', debug_light: 0 })],
  ['shadow.directional on a spot light', 'reject', spot({ shadow: { directional: { mode: 'fit' } } })],
  ['shadow.directional on a point light', 'reject', point({ shadow: { directional: { cascades: 2 } } })],
  ['contact shadows on a light whose shadows are off', 'reject', light0({ shadow: { enabled: false, contact: { enabled: true } } })],
  ['contact shadows on a light, root shadows off', 'reject', doc((d) => { d.shadows = { enabled: false }; d.lights[0].shadow = contactOn; })],
  ['contact shadows on a light, root shadows false', 'reject', doc((d) => { d.shadows = false; d.lights[0].shadow = contactOn; })],
  ['ground-placed plane with size', 'reject', ground({ size: [4, 4] })],
  ['ground-placed plane with a transform', 'reject', ground({ transform: { translation: [0, 1, 0] } })],
  ['margin without placement', 'reject', doc((d) => d.objects.push({ shape: 'plane', margin: 2 }))],
  ['camera direction without fit', 'reject', cam({ position: [4, 3, 4], target: [0, 0, 0], direction: [1, 0, 0] })],
  ['"shadows": null without a preset', 'reject', doc((d) => { d.shadows = null; })],
  ['"lights": null without a preset', 'reject', doc((d) => { d.lights = null; })],
  ['unknown root member', 'reject', doc((d) => { d.colour = 1; })],
  ['unknown camera member', 'reject', cam({ position: [4, 3, 4], target: [0, 0, 0], zoom: 2 })],
  ['width 0', 'reject', doc((d) => { d.width = 0; })],
  ['width as a string', 'reject', doc((d) => { d.width = '8'; })],
  ['no objects', 'reject', doc((d) => { delete d.objects; })],
  ['no camera, views or turntable', 'reject', doc((d) => { delete d.camera; })],
  ['views and turntable together', 'reject', doc((d) => { d.views = [{}]; d.turntable = { frames: 2 }; })],
  ['light without type', 'reject', doc((d) => { d.lights = [{ direction: [0, -1, 0] }]; })],
  ['directional light without direction', 'reject', doc((d) => { d.lights = [{ type: 'directional' }]; })],
  ['spot light without position', 'reject', doc((d) => { d.lights = [{ type: 'spot', direction: [0, -1, 0] }]; })],
  ['format jpeg', 'reject', out({ format: 'jpeg' })],
  ['quality with format png', 'reject', out({ format: 'png', quality: 80 })],
  ['quality 101', 'reject', out({ format: 'webp', quality: 101 })],
  ['aovs with format png', 'reject', out({ format: 'png', aovs: ['depth'] })],
  ['aovs with format webp', 'reject', out({ format: 'webp', aovs: ['depth'] })],
  ['aovs with format avif', 'reject', out({ format: 'avif', aovs: ['depth'] })],
  ['quality with format exr', 'reject', out({ format: 'exr', quality: 70 })],
  ['bit_depth 12', 'reject', out({ bit_depth: 12 })],
  ['msaa 2', 'reject', out({ msaa: 2 })],
  ['preset with "camera": null and no views (the camera is then missing)', 'reject', preset({ camera: null })],
  ['preset with "objects": null', 'reject', preset({ objects: null })],
  ['unknown preset', 'reject', preset({ preset: 'poster' })],
  ['sphere radius 0', 'reject', doc((d) => { d.objects[0].radius = 0; })],
  ['box size with two numbers', 'reject', doc((d) => d.objects.push({ shape: 'box', size: [1, 1] }))],

  // ---- rejected by rules the schema cannot state (its description lists them) ----
  ['inner_angle greater than outer_angle', 'server', spot({ inner_angle: 40, outer_angle: 30 })],
  ['debug_light naming no light', 'server', out({ debug: 'shadow', debug_light: 3 })],
  ['a material name that does not exist', 'server', doc((d) => { d.objects[0].material = 'nowhere'; })],
  ['far not greater than near', 'server', cam({ position: [4, 3, 4], target: [0, 0, 0], near: 5, far: 1 })],
  ['mesh positions not a multiple of 3', 'server', doc((d) => d.objects.push({ shape: 'mesh', positions: [0, 0, 0, 1] }))],
];
