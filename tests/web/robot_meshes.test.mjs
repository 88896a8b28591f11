// A robot with mesh visuals, as most real URDFs have: a temporary ROS package with an STL
// (binary), an OBJ and a DAE, a two-link URDF naming them through package://, one mesh that is
// not there and one the browser cannot draw. `serve --package-path` delivers exactly the files
// the URDF names (nothing else, whatever the request asks), the page draws them in the robot and
// its ghost (checked in the scene graph), and both kinds of missing mesh show a visible warning.
import { describe, it, before, after } from 'node:test';
import assert from 'node:assert/strict';
import http from 'node:http';
import { mkdirSync, mkdtempSync, readFileSync, rmSync, writeFileSync } from 'node:fs';
import { tmpdir } from 'node:os';
import path from 'node:path';
import { startServer, launchChromium, openPage, waitFor, closeAll } from './support.mjs';
import { MeshFormat, ShapeKind } from '../../web/js/protocol.js';

const hooks = (page, f, arg) => page.evaluate(f, arg);

// A box's 12 triangles as a binary STL: 80-byte header, count, 50 bytes per triangle.
function binaryStlBox([sx, sy, sz]) {
  const v = (i) => [(i & 1 ? 0.5 : -0.5) * sx, (i & 2 ? 0.5 : -0.5) * sy, (i & 4 ? 0.5 : -0.5) * sz];
  const faces = [[0, 2, 1], [1, 2, 3], [4, 5, 6], [5, 7, 6], [0, 1, 4], [1, 5, 4],
    [2, 6, 3], [3, 6, 7], [0, 4, 2], [2, 4, 6], [1, 3, 5], [3, 7, 5]];
  const buffer = Buffer.alloc(84 + 50 * faces.length);
  buffer.write('shapectl test box', 0);
  buffer.writeUInt32LE(faces.length, 80);
  faces.forEach((face, k) => {
    let at = 84 + 50 * k + 12;  // the normal stays 0: the loader's normals are recomputed
    for (const i of face) for (const c of v(i)) { buffer.writeFloatLE(c, at); at += 4; }
  });
  return buffer;
}

// The same box as OBJ text (quads: the loader splits them into triangles).
function objBox([sx, sy, sz]) {
  const lines = [];
  for (let i = 0; i < 8; i++)
    lines.push(`v ${(i & 1 ? 0.5 : -0.5) * sx} ${(i & 2 ? 0.5 : -0.5) * sy} ${(i & 4 ? 0.5 : -0.5) * sz}`);
  for (const f of [[1, 3, 4, 2], [5, 6, 8, 7], [1, 2, 6, 5], [3, 7, 8, 4], [1, 5, 7, 3], [2, 4, 8, 6]])
    lines.push(`f ${f.join(' ')}`);
  return `${lines.join('\n')}\n`;
}

// One red triangle, with its own material (the URDF gives this visual no colour).
const DAE_TRIANGLE = `<?xml version="1.0" encoding="utf-8"?>
<COLLADA xmlns="http://www.collada.org/2005/11/COLLADASchema" version="1.4.1">
  <asset><unit name="meter" meter="1"/><up_axis>Y_UP</up_axis></asset>
  <library_effects><effect id="red-effect"><profile_COMMON><technique sid="common"><lambert>
    <diffuse><color sid="diffuse">0.8 0.1 0.1 1</color></diffuse>
  </lambert></technique></profile_COMMON></effect></library_effects>
  <library_materials><material id="red" name="red"><instance_effect url="#red-effect"/></material></library_materials>
  <library_geometries><geometry id="tri" name="tri"><mesh>
    <source id="tri-pos"><float_array id="tri-pos-array" count="9">0 0 0 0.05 0 0 0 0.05 0</float_array>
      <technique_common><accessor source="#tri-pos-array" count="3" stride="3">
        <param name="X" type="float"/><param name="Y" type="float"/><param name="Z" type="float"/>
      </accessor></technique_common></source>
    <vertices id="tri-vtx"><input semantic="POSITION" source="#tri-pos"/></vertices>
    <triangles material="red-material" count="1"><input semantic="VERTEX" source="#tri-vtx" offset="0"/><p>0 1 2</p></triangles>
  </mesh></geometry></library_geometries>
  <library_visual_scenes><visual_scene id="scene"><node id="n" name="n">
    <instance_geometry url="#tri"><bind_material><technique_common>
      <instance_material symbol="red-material" target="#red"/>
    </technique_common></bind_material></instance_geometry>
  </node></visual_scene></library_visual_scenes>
  <scene><instance_visual_scene url="#scene"/></scene>
</COLLADA>
`;

const BASE_RGBA = [0.2, 0.4, 0.6, 1];

// base (fixed, holding one end of the bar) carries the STL in a URDF colour; arm (revolute about
// z, its tool at the bar's other end) the OBJ, the DAE, a missing STL and an OBJ without faces.
function urdfText() {
  const mesh = (file, extra = '') => `<visual><geometry><mesh filename="package://mesh_bot/meshes/${file}"${extra}/></geometry></visual>`;
  return `<?xml version="1.0"?>
<robot name="mesh_bot">
  <link name="base">
    <visual><origin xyz="0 0 0.05"/><geometry><mesh filename="package://mesh_bot/meshes/base.stl" scale="0.001 0.001 0.001"/></geometry>
      <material name="blue"><color rgba="${BASE_RGBA.join(' ')}"/></material></visual>
  </link>
  <joint name="swing" type="revolute">
    <parent link="base"/><child link="arm"/><origin xyz="0 0 0.2"/><axis xyz="0 0 1"/>
    <limit lower="-1" upper="1" velocity="1" effort="10"/>
  </joint>
  <link name="arm">
    ${mesh('arm.obj')}
    ${mesh('hand.dae')}
    ${mesh('gone.stl')}
    ${mesh('empty.obj')}
  </link>
</robot>
`;
}

// A 10 cm bar from x = 0.25 to 0.35 at z = 0.2, held by the arm's tool at its near end and by the
// base at its far end.
const SCENE = {
  object: {
    mesh: { box: { size: [0.1, 0.02, 0.02], cells: [5, 2, 2] } },
    material: { youngs_modulus: 2e5, poisson_ratio: 0.3, density: 40 },
    pose: { position: [0.3, 0, 0.2], rpy: [0, 0, 0] },
  },
  gravity: [0, 0, -9.81],
  robot: {
    urdf: 'robot/mesh_bot.urdf',
    end_effectors: [{ name: 'tool', link: 'arm', tcp: [0.25, 0, 0] }, { name: 'holder', link: 'base', tcp: [0.35, 0, 0.2] }],
  },
  grips: [
    { end_effector: 'tool', region: { box: { min: [-0.051, -0.011, -0.011], max: [-0.049, 0.011, 0.011] } } },
    { end_effector: 'holder', region: { box: { min: [0.049, -0.011, -0.011], max: [0.051, 0.011, 0.011] } } },
  ],
};

// GET `target` sent as is (no URL normalisation, unlike fetch): status, content type, body.
function rawGet(port, target) {
  return new Promise((resolve, reject) => {
    const request = http.request({ host: '127.0.0.1', port, path: target, method: 'GET' }, (response) => {
      const chunks = [];
      response.on('data', (c) => chunks.push(c));
      response.on('end', () => resolve({ status: response.statusCode, type: response.headers['content-type'], body: Buffer.concat(chunks) }));
    });
    request.on('error', reject);
    request.end();
  });
}

describe('robot mesh visuals (package:// STL, OBJ, DAE)', () => {
  let dir, files, server, browser, page, scene;
  before(async () => {
    dir = mkdtempSync(path.join(tmpdir(), 'shapectl-meshes-'));
    const meshes = path.join(dir, 'share', 'mesh_bot', 'meshes');
    mkdirSync(meshes, { recursive: true });
    mkdirSync(path.join(dir, 'robot'));
    files = {
      'base.stl': binaryStlBox([100, 100, 100]),  // mm, scaled by the URDF
      'arm.obj': Buffer.from(objBox([0.25, 0.03, 0.03])),
      'hand.dae': Buffer.from(DAE_TRIANGLE),
      'empty.obj': Buffer.from('v 0 0 0\nv 1 0 0\n'),  // no faces: nothing to draw
    };
    for (const [name, bytes] of Object.entries(files)) writeFileSync(path.join(meshes, name), bytes);
    writeFileSync(path.join(dir, 'robot', 'mesh_bot.urdf'), urdfText());
    writeFileSync(path.join(dir, 'secret.txt'), 'not for the page\n');
    writeFileSync(path.join(dir, 'scene.json'), JSON.stringify(SCENE));
    server = await startServer([path.join(dir, 'scene.json'), '--robot', 'sim', '--package-path', path.join(dir, 'share')]);
    browser = await launchChromium();
    page = await openPage(browser, server.url);
    scene = await hooks(page, () => window.shapectl.scene);
  });
  after(async () => {
    try {
      await closeAll(browser, server);
    } finally {
      if (dir) rmSync(dir, { recursive: true, force: true });
    }
  });

  // The scene message's mesh visuals, by file name.
  const meshVisuals = () => Object.fromEntries(scene.robot.links.flatMap((link) => link.visuals
    .filter((v) => v.kind === ShapeKind.Mesh).map((v) => [path.basename(v.file), { ...v, link: link.name }])));

  it('describes each mesh visual with url, format, scale, colour, and warns about the missing one', () => {
    const v = meshVisuals();
    assert.deepEqual(Object.keys(v).sort(), ['arm.obj', 'base.stl', 'empty.obj', 'gone.stl', 'hand.dae']);
    assert.equal(v['base.stl'].format, MeshFormat.Stl);
    assert.deepEqual(v['base.stl'].scale, [0.001, 0.001, 0.001]);
    BASE_RGBA.forEach((c, i) => assert.ok(Math.abs(v['base.stl'].color[i] - c) < 1e-6, `URDF colour ${v['base.stl'].color}`));  // urdfdom's floats
    assert.equal(v['hand.dae'].format, MeshFormat.Dae);
    assert.equal(v['hand.dae'].color, null);
    for (const name of ['base.stl', 'arm.obj', 'hand.dae', 'empty.obj'])
      assert.match(v[name].url, new RegExp(`^/robot-mesh/\\d+\\.${v[name].format}$`), name);
    assert.equal(v['gone.stl'].url, null);
    const urdf = path.join(dir, 'robot', 'mesh_bot.urdf');
    assert.equal(scene.warnings.length, 1, JSON.stringify(scene.warnings));
    assert.ok(scene.warnings[0].startsWith(`${urdf}: link 'arm': visual mesh 'package://mesh_bot/meshes/gone.stl' not found`), scene.warnings[0]);
    assert.match(server.log, /warning: .*mesh_bot\.urdf: link 'arm': visual mesh 'package:\/\/mesh_bot\/meshes\/gone\.stl' not found/);
  });

  it('serves exactly the files the URDF names, with their content type', async () => {
    const types = { stl: 'model/stl', obj: 'model/obj', dae: 'model/vnd.collada+xml' };
    const v = meshVisuals();
    for (const name of Object.keys(files)) {
      const reply = await rawGet(server.port, v[name].url);
      assert.equal(reply.status, 200, name);
      assert.equal(reply.type, types[v[name].format], name);
      assert.ok(reply.body.equals(files[name]), `${name}: the file's bytes`);
    }
    const stl = v['base.stl'].url;
    for (const target of ['/robot-mesh/999.stl', '/robot-mesh/999', stl.replace('.stl', '.obj'), stl.replace(/(\d+)/, '0$1'),
      '/robot-mesh/../secret.txt', '/robot-mesh/..%2f..%2fsecret.txt', `/robot-mesh/${path.join(dir, 'secret.txt')}`,
      `${stl}/../../secret.txt`, '/robot-mesh/-1.stl', '/robot-mesh/'])
      assert.equal((await rawGet(server.port, target)).status, 404, target);
  });

  it('draws the meshes in the robot and its ghost, in the URDF colour or the DAE\'s own', async () => {
    const drawn = await waitFor(async () => {
      const m = await hooks(page, () => window.shapectl.robotMeshes());
      return m.every((e) => e.state !== 'loading') && m;
    }, 'every mesh loaded or failed');
    const byFile = Object.fromEntries(drawn.map((m) => [path.basename(m.file), m]));
    assert.equal(byFile['base.stl'].state, 'loaded');
    assert.equal(byFile['base.stl'].vertices, 36);  // 12 triangles
    assert.equal(byFile['arm.obj'].state, 'loaded');
    assert.equal(byFile['arm.obj'].vertices, 36);  // 6 quads, 2 triangles each
    assert.equal(byFile['hand.dae'].state, 'loaded');
    assert.equal(byFile['hand.dae'].vertices, 3);
    assert.equal(byFile['gone.stl'].state, 'missing');
    assert.equal(byFile['empty.obj'].state, 'failed');
    assert.ok(['base.stl', 'arm.obj', 'hand.dae'].every((f) => byFile[f].visible), 'shown');

    const colors = Object.fromEntries((await hooks(page, () => window.shapectl.robotColors())).map((l) => [l.name, l.visuals]));
    BASE_RGBA.slice(0, 3).forEach((c, i) => assert.ok(Math.abs(colors.base[0].rgb[i] - c) < 1e-3, `base STL in the URDF colour: ${colors.base[0].rgb}`));
    const [r, g, b] = colors.arm[1].rgb;  // the DAE: its own red
    assert.ok(r > 0.5 && g < 0.3 && b < 0.3, `DAE in its own material: ${colors.arm[1].rgb}`);

    const ghost = await waitFor(async () => {
      const m = await hooks(page, () => window.shapectl.ghost().meshVisuals);
      return m.every((e) => e.state !== 'loading') && m;
    }, 'the ghost\'s meshes loaded');
    assert.deepEqual(ghost.map((m) => [m.state, m.vertices]), drawn.map((m) => [m.state, m.vertices]), 'the ghost has the same meshes');
    assert.deepEqual(page.problems, []);
  });

  it('shows a visible warning for the missing mesh and for the one the browser could not draw', async () => {
    const text = await waitFor(async () => {
      const t = await hooks(page, () => {
        const box = document.getElementById('robot-warnings');
        return !box.hidden && box.getBoundingClientRect().height > 0 ? box.textContent : '';
      });
      return t.includes('empty.obj') && t;
    }, 'the warning line names both meshes');
    assert.match(text, /link 'arm': visual mesh 'package:\/\/mesh_bot\/meshes\/gone\.stl' not found/);
    assert.match(text, /link 'arm': mesh 'package:\/\/mesh_bot\/meshes\/empty\.obj' .*could not be drawn: no triangles/);
  });
});
