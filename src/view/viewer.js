// src/view/viewer.js — the viewer page's script (posefilter/view.h, docs/VIEWER.md). It reads
// the JSON of <script id="posefilter-data"> (layout: src/view/view_html.cc) and draws it with
// three.js (the global THREE, inlined before this script).
//
// Frames: the data is in the depth camera's frame (OpenCV: x right, y down, z forward,
// metres). Everything hangs under one group turned by pi about x, so that three's world is
// the same camera frame seen the OpenGL way (y up, looking down -z); the depth camera sits at
// the world origin.
//
// URL hash (all optional, "&"-separated): view=camera (the depth camera's own viewpoint and
// intrinsics, the canvas the image's size, no panel), show=cloud,est,gt,plane,particles,top
// (the layers drawn; default all but top), flat=1 (estimates in flat red, unlit), iter=N (the slider; negative
// counts from the end), obj=I (particles of object I only), orbit=TURN,TILT,ZOOM (the start
// view turned TURN degrees about the vertical and TILT degrees up, its distance times ZOOM), panels=LAYERS@ITER;... (with
// view=camera: one image-sized panel per entry, stacked top to bottom, each drawing LAYERS
// ('+'-separated) at slider value ITER).
(function () {
  'use strict';
  const status = (s) => { document.body.dataset.status = s; };
  window.addEventListener('error', (e) => {
    status('error: ' + e.message);
    const div = document.createElement('div');
    div.id = 'error';
    div.textContent = 'viewer error: ' + e.message;
    document.body.appendChild(div);
  });
  const data = JSON.parse(document.getElementById('posefilter-data').textContent);
  const hash = {};
  for (const kv of location.hash.replace(/^#/, '').split('&')) {
    if (!kv) continue;
    const i = kv.indexOf('=');
    hash[decodeURIComponent(i < 0 ? kv : kv.slice(0, i))] = i < 0 ? '1' : decodeURIComponent(kv.slice(i + 1));
  }
  const cameraView = hash.view === 'camera';
  const flat = hash.flat === '1';

  function bytes(b64) {
    const s = atob(b64);
    const out = new Uint8Array(s.length);
    for (let i = 0; i < s.length; ++i) out[i] = s.charCodeAt(i);
    return out.buffer;
  }
  const f32 = (b64) => new Float32Array(bytes(b64));

  // Weight in [0, 1] -> colour (a perceptual ramp from dark violet through blue, green and
  // yellow to red; the legend of the panel shows the same stops).
  const ramp = [[0x30, 0x12, 0x3b], [0x46, 0x86, 0xfb], [0x1a, 0xe4, 0xb6], [0xa2, 0xfc, 0x3c], [0xfa, 0xbb, 0x39],
                [0xe4, 0x46, 0x0a]];
  function rampColour(t, out, k) {
    const x = Math.min(Math.max(t, 0), 1) * (ramp.length - 1);
    const i = Math.min(Math.floor(x), ramp.length - 2), f = x - i;
    for (let c = 0; c < 3; ++c) out[k + c] = (ramp[i][c] + f * (ramp[i + 1][c] - ramp[i][c])) / 255;
  }

  const cam = data.camera;
  const W = cam.width, H = cam.height;
  const renderer = new THREE.WebGLRenderer({antialias: !cameraView, preserveDrawingBuffer: true});
  renderer.setPixelRatio(cameraView ? 1 : window.devicePixelRatio);
  document.body.appendChild(renderer.domElement);
  const scene = new THREE.Scene();
  scene.background = new THREE.Color(cameraView ? 0x000000 : 0x111111);
  const root = new THREE.Group();
  root.rotation.x = Math.PI;  // OpenCV camera frame -> three's world
  scene.add(root);
  scene.add(new THREE.AmbientLight(0xffffff, 0.55));
  const light = new THREE.DirectionalLight(0xffffff, 0.6);
  scene.add(light);

  const layers = {cloud: new THREE.Group(), est: new THREE.Group(), gt: new THREE.Group(), plane: new THREE.Group(),
                  particles: new THREE.Group(), top: new THREE.Group()};
  for (const k in layers) root.add(layers[k]);

  // The point cloud.
  {
    const c = data.cloud, depth = f32(c.depth), rgb = new Uint8Array(bytes(c.rgb));
    const pos = [], col = [];
    for (let i = 0; i < c.h; ++i)
      for (let j = 0; j < c.w; ++j) {
        const k = i * c.w + j, z = depth[k];
        if (!(z > 0)) continue;
        const u = j * c.step, v = i * c.step;
        pos.push((u - cam.cx) * z / cam.fx, (v - cam.cy) * z / cam.fy, z);
        col.push(rgb[3 * k] / 255, rgb[3 * k + 1] / 255, rgb[3 * k + 2] / 255);
      }
    const g = new THREE.BufferGeometry();
    g.setAttribute('position', new THREE.Float32BufferAttribute(pos, 3));
    g.setAttribute('color', new THREE.Float32BufferAttribute(col, 3));
    layers.cloud.add(new THREE.Points(g, new THREE.PointsMaterial({size: 2, sizeAttenuation: false, vertexColors: true})));
  }

  // Support planes: translucent rectangles.
  for (const p of data.planes) {
    const g = new THREE.BufferGeometry();
    g.setAttribute('position', new THREE.Float32BufferAttribute([].concat(...p.corners), 3));
    g.setIndex([0, 1, 2, 0, 2, 3]);
    layers.plane.add(new THREE.Mesh(g, new THREE.MeshBasicMaterial(
        {color: 0xc8c8ff, transparent: true, opacity: 0.25, side: THREE.DoubleSide, depthWrite: false})));
  }

  function matrix4(m) {  // 16 numbers, row-major
    return new THREE.Matrix4().set(...m);
  }
  function placed(geometry, material, m) {
    const mesh = new THREE.Mesh(geometry, material);
    mesh.matrixAutoUpdate = false;
    mesh.matrix.copy(m);
    return mesh;
  }

  // Meshes, estimates, ground truth, and each object's particle data.
  const objects = data.objects.map((o) => {
    const g = new THREE.BufferGeometry();
    g.setAttribute('position', new THREE.BufferAttribute(f32(o.vertices), 3));
    g.setIndex(new THREE.BufferAttribute(new Uint32Array(bytes(o.faces)), 1));
    g.computeVertexNormals();
    const estMat = flat ? new THREE.MeshBasicMaterial({color: 0xff0000, side: THREE.DoubleSide})
                        : new THREE.MeshLambertMaterial({color: 0x40d060, side: THREE.DoubleSide, transparent: true,
                                                         opacity: 0.6, depthWrite: false});
    layers.est.add(placed(g, estMat, matrix4(o.estimate)));
    if (o.gt)
      layers.gt.add(placed(g, new THREE.MeshBasicMaterial({color: 0x4080ff, wireframe: true, transparent: true,
                                                           opacity: 0.6}), matrix4(o.gt)));
    const offsets = [0];
    for (const s of o.sets) offsets.push(offsets[offsets.length - 1] + s.count);
    return {o, geometry: g, points: f32(o.points), weights: new Uint16Array(bytes(o.weights)), top: f32(o.top),
            offsets};
  });
  const maxSets = Math.max(0, ...objects.map((x) => x.o.sets.length));

  // The particles of slider value `it` (each object: its set min(it, sets - 1)).
  const onlyObj = hash.obj === undefined ? -1 : Number(hash.obj);
  function showIteration(it) {
    for (const l of [layers.particles, layers.top])
      while (l.children.length) {
        const c = l.children.pop();
        if (c.isPoints) c.geometry.dispose();
      }
    const lines = [];
    objects.forEach((x, idx) => {
      const sets = x.o.sets;
      if (!sets.length || (onlyObj >= 0 && idx !== onlyObj)) return;
      const s = Math.min(it, sets.length - 1), set = sets[s];
      const a = x.offsets[s], n = set.count;
      const col = new Float32Array(3 * n);
      for (let i = 0; i < n; ++i) rampColour(x.weights[a + i] / 65535, col, 3 * i);
      const g = new THREE.BufferGeometry();
      g.setAttribute('position', new THREE.BufferAttribute(x.points.slice(3 * a, 3 * (a + n)), 3));
      g.setAttribute('color', new THREE.BufferAttribute(col, 3));
      layers.particles.add(new THREE.Points(g, new THREE.PointsMaterial({size: 4, sizeAttenuation: false,
                                                                           vertexColors: true})));
      const K = x.o.top_k;
      for (let k = 0; k < Math.min(K, set.total); ++k) {
        const t = x.top.subarray(12 * (s * K + k), 12 * (s * K + k + 1));
        const m = new THREE.Matrix4().set(t[0], t[1], t[2], t[3], t[4], t[5], t[6], t[7], t[8], t[9], t[10], t[11],
                                          0, 0, 0, 1);
        const c = [0, 0, 0];
        rampColour(k === 0 ? set.best : x.weights[a + Math.min(k, n - 1)] / 65535, c, 0);
        layers.top.add(placed(x.geometry, new THREE.MeshBasicMaterial(
            {color: new THREE.Color(c[0], c[1], c[2]), wireframe: true, transparent: true, opacity: k ? 0.3 : 0.7}), m));
      }
      lines.push(x.o.name + ': run ' + set.run + ', iteration ' + set.iteration + ', ' + set.total +
                 ' particles, best ' + set.best.toFixed(3));
    });
    return lines;
  }

  const camera = new THREE.PerspectiveCamera(50, 1, 0.01, 100);
  // The depth camera's projection (pixel centres at integer OpenCV coordinates).
  function setIntrinsics(near, far) {
    const p = new THREE.Matrix4().set(
        2 * cam.fx / W, 0, (W - 2 * cam.cx - 1) / W, 0,
        0, 2 * cam.fy / H, (2 * cam.cy + 1 - H) / H, 0,
        0, 0, -(far + near) / (far - near), -2 * far * near / (far - near),
        0, 0, -1, 0);
    camera.projectionMatrix.copy(p);
    camera.projectionMatrixInverse.getInverse(p);
  }

  // The orbit: the camera circles `target` at `radius`, turned by theta (about y) and phi
  // (elevation).
  const orbit = {target: new THREE.Vector3(), radius: 1, theta: 0, phi: 0};
  {
    // Start at the depth camera looking at the estimates' centre (or the cloud's middle).
    scene.updateMatrixWorld(true);
    const c = new THREE.Vector3();
    let n = 0;
    for (const l of [layers.est, layers.cloud]) {
      if (n) break;
      new THREE.Box3().setFromObject(l).getCenter(c);
      n = l.children.length && isFinite(c.x) ? 1 : 0;
    }
    orbit.target.copy(n ? c : new THREE.Vector3(0, 0, -1));
    orbit.radius = orbit.target.length();
    orbit.phi = Math.asin(Math.max(-1, Math.min(1, -orbit.target.y / orbit.radius)));
    orbit.theta = Math.atan2(-orbit.target.x, -orbit.target.z);
  }
  const home = Object.assign({}, orbit, {target: orbit.target.clone()});
  if (hash.orbit) {  // orbit=TURN,TILT,ZOOM: degrees about the vertical, degrees up, distance factor
    const [turn, tilt, zoom] = hash.orbit.split(',').map(Number);
    orbit.theta += (turn || 0) * Math.PI / 180;
    orbit.phi = Math.max(-1.55, Math.min(1.55, orbit.phi + (tilt || 0) * Math.PI / 180));
    orbit.radius *= zoom > 0 ? zoom : 1;
  }
  function placeCamera() {
    const o = orbit;
    camera.position.set(o.target.x + o.radius * Math.cos(o.phi) * Math.sin(o.theta),
                        o.target.y + o.radius * Math.sin(o.phi),
                        o.target.z + o.radius * Math.cos(o.phi) * Math.cos(o.theta));
    camera.up.set(0, 1, 0);
    camera.lookAt(o.target);
    light.position.copy(camera.position);
  }

  function setVisible(list) {
    for (const k in layers) layers[k].visible = list.includes(k);
  }
  const defaultLayers = 'cloud,est,gt,plane,particles';
  const shown = (hash.show || defaultLayers).split(',');
  setVisible(shown);

  function render() {
    if (!cameraView) {
      placeCamera();
      renderer.render(scene, camera);
    }
  }

  // The slider: its input event redraws the particles (the URL's iter sets it the same way).
  const slider = document.createElement('input');
  slider.type = 'range';
  slider.min = 0;
  slider.max = Math.max(0, maxSets - 1);
  const info = document.createElement('div');
  slider.addEventListener('input', () => {
    info.innerHTML = '';
    for (const line of showIteration(Number(slider.value))) {
      const d = document.createElement('div');
      d.textContent = line;
      info.appendChild(d);
    }
    document.body.dataset.iteration = slider.value;
    render();
  });
  function setSlider(v) {
    let it = Number(v);
    if (it < 0) it += maxSets;
    slider.value = Math.max(0, Math.min(maxSets - 1, it));
    slider.dispatchEvent(new Event('input'));
  }

  if (cameraView) {
    const panels = hash.panels ? hash.panels.split(';') : [(hash.show || defaultLayers) + '@' + (hash.iter || '-1')];
    renderer.setSize(W, H * panels.length);
    renderer.autoClear = false;
    renderer.setScissorTest(true);
    camera.position.set(0, 0, 0);
    camera.rotation.set(0, 0, 0);
    camera.updateMatrixWorld();
    setIntrinsics(0.01, 100);
    panels.forEach((p, i) => {
      const [list, it] = p.split('@');
      setVisible(list.split(/[+,]/));
      setSlider(it === undefined ? -1 : it);
      const y = (panels.length - 1 - i) * H;  // GL viewports count from the bottom
      renderer.setViewport(0, y, W, H);
      renderer.setScissor(0, y, W, H);
      renderer.clear();
      renderer.render(scene, camera);
    });
  } else {
    const panel = document.createElement('div');
    panel.id = 'panel';
    const title = document.createElement('div');
    title.style.fontWeight = 'bold';
    title.textContent = data.title || 'posefilter view';
    panel.appendChild(title);
    const names = {cloud: 'point cloud', est: 'estimates', gt: 'ground truth', plane: 'support plane',
                   particles: 'particles', top: 'best particles as meshes'};
    for (const k in layers) {
      const row = document.createElement('label');
      row.className = 'row';
      row.style.display = 'block';
      const box = document.createElement('input');
      box.type = 'checkbox';
      box.checked = layers[k].visible;
      box.addEventListener('change', () => { layers[k].visible = box.checked; render(); });
      row.append(box, ' ' + names[k]);
      panel.appendChild(row);
    }
    const est = document.createElement('div');
    est.className = 'row';
    est.textContent = data.objects.map((o) => o.name + ' ' + o.weight.toFixed(3)).join(', ') || 'no objects';
    panel.append(est);
    if (maxSets) {
      const legend = document.createElement('div');
      legend.className = 'row';
      legend.innerHTML = '<div>particle weight 0 &rarr; 1</div><div id="legend"></div>';
      panel.append(slider, info, legend);
    } else {
      info.textContent = 'no particle history recorded';
      panel.append(info);
    }
    const help = document.createElement('div');
    help.className = 'row';
    help.style.color = '#999';
    help.textContent = 'drag: turn, right drag: pan, wheel: zoom, double click: the depth camera\'s view';
    panel.append(help);
    document.body.appendChild(panel);

    const resize = () => {
      renderer.setSize(window.innerWidth, window.innerHeight);
      camera.aspect = window.innerWidth / window.innerHeight;
      camera.fov = 2 * Math.atan(H / 2 / cam.fy) * 180 / Math.PI;
      camera.updateProjectionMatrix();
      render();
    };
    window.addEventListener('resize', resize);
    const el = renderer.domElement;
    let drag = null;
    el.addEventListener('contextmenu', (e) => e.preventDefault());
    el.addEventListener('pointerdown', (e) => {
      drag = {x: e.clientX, y: e.clientY, pan: e.button !== 0 || e.shiftKey};
      el.setPointerCapture(e.pointerId);
    });
    el.addEventListener('pointerup', () => { drag = null; });
    el.addEventListener('pointermove', (e) => {
      if (!drag) return;
      const dx = e.clientX - drag.x, dy = e.clientY - drag.y;
      drag.x = e.clientX;
      drag.y = e.clientY;
      if (drag.pan) {
        const s = orbit.radius * 2 * Math.tan(camera.fov * Math.PI / 360) / el.clientHeight;
        const right = new THREE.Vector3().setFromMatrixColumn(camera.matrixWorld, 0);
        const up = new THREE.Vector3().setFromMatrixColumn(camera.matrixWorld, 1);
        orbit.target.addScaledVector(right, -dx * s).addScaledVector(up, dy * s);
      } else {
        orbit.theta -= dx * 0.005;
        orbit.phi = Math.max(-1.55, Math.min(1.55, orbit.phi + dy * 0.005));
      }
      render();
    });
    el.addEventListener('wheel', (e) => {
      e.preventDefault();
      orbit.radius = Math.max(0.02, orbit.radius * Math.exp(e.deltaY * 0.001));
      render();
    }, {passive: false});
    el.addEventListener('dblclick', () => {
      Object.assign(orbit, home, {target: home.target.clone()});
      render();
    });
    resize();
    setSlider(hash.iter === undefined ? -1 : hash.iter);
  }
  document.body.dataset.objects = String(data.objects.length);
  document.body.dataset.sets = String(maxSets);
  if (!document.body.dataset.status) status('ready');
})();
