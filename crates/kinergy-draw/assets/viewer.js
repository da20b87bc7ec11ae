// The page of `kinergy view` (kinergy_draw::viewer): clips overlaid in 3-D with three.js, a
// hand-speed chart synced to the scrubber, and what it loaded and shows reported on <body>'s
// data attributes and the console, for people and for the browser test.
//
// The data (JSON in #kinergy-data) are world positions in meters, Y up, per frame, as Kinergy's
// forward kinematics computed them; each clip plays at its own frame rate and all clips share
// one clock (the frame shown is the nearest to the time, the last one after a clip's end).
//
// Address options: #t=SECONDS or #frame=N (of the first clip) seek there and pause; #paused
// starts paused at 0; #view=WxH fixes the 3-D view's size (CSS pixels). Options combine with
// commas: #frame=40,view=800x450.
(function () {
  'use strict';
  const data = JSON.parse(document.getElementById('kinergy-data').textContent);
  const body = document.body;
  const report = body.dataset;
  const clips = data.clips;

  // ---- time ------------------------------------------------------------------------------
  const duration = Math.max(0, ...clips.map((c) => (c.frames - 1) * c.frame_time));
  const finest = Math.min(...clips.map((c) => c.frame_time));
  const frameAt = (clip, t) =>
    Math.min(clip.frames - 1, Math.max(0, Math.round(t / clip.frame_time)));
  let time = 0;
  let playing = true;
  let speed = 1;

  const hash = new URLSearchParams(location.hash.replace(/^#/, '').replace(/,/g, '&'));
  if (hash.has('t')) {
    time = Number(hash.get('t')) || 0;
    playing = false;
  } else if (hash.has('frame')) {
    time = (Number(hash.get('frame')) || 0) * clips[0].frame_time;
    playing = false;
  }
  if (hash.has('paused')) playing = false;
  time = Math.min(Math.max(time, 0), duration);

  // ---- the 3-D view ----------------------------------------------------------------------
  const view = document.getElementById('view');
  const canvas = document.getElementById('scene');
  // #view=WxH: the 3-D view at a fixed size in CSS pixels (pictures and tests that must not
  // depend on the window).
  const fixed = (hash.get('view') || '').split('x').map(Number);
  if (fixed.length === 2 && fixed.every((v) => v > 0 && v <= 8192)) {
    view.style.flex = 'none';
    view.style.width = fixed[0] + 'px';
    view.style.height = fixed[1] + 'px';
  }
  let renderer = null;
  try {
    renderer = new THREE.WebGLRenderer({ canvas, antialias: false });
  } catch (e) {
    report.webgl = 'no';
    document.getElementById('nogl').hidden = false;
    console.log('kinergy-view: no WebGL: ' + e.message);
  }
  if (renderer) report.webgl = 'yes';
  const scene = new THREE.Scene();
  scene.background = new THREE.Color(0xffffff);
  scene.add(new THREE.HemisphereLight(0xffffff, 0x888888, 2.0));
  const sun = new THREE.DirectionalLight(0xffffff, 1.5);
  sun.position.set(2, 4, 3);
  scene.add(sun);

  // The bounds of every clip's every frame (and the target): the camera frames them all.
  const lo = new THREE.Vector3(Infinity, Infinity, Infinity);
  const hi = new THREE.Vector3(-Infinity, -Infinity, -Infinity);
  const grow = (x, y, z) => {
    lo.set(Math.min(lo.x, x), Math.min(lo.y, y), Math.min(lo.z, z));
    hi.set(Math.max(hi.x, x), Math.max(hi.y, y), Math.max(hi.z, z));
  };
  for (const c of clips) {
    const p = c.positions;
    for (let i = 0; i < p.length; i += 3) grow(p[i], p[i + 1], p[i + 2]);
  }
  if (data.target) grow(...data.target);
  const center = lo.clone().add(hi).multiplyScalar(0.5);
  const size = Math.max(hi.x - lo.x, hi.y - lo.y, hi.z - lo.z, 0.5);

  // A floor of 25 cm squares under everything.
  const floor = Math.ceil(Math.max(hi.x - lo.x, hi.z - lo.z) + 2);
  const grid = new THREE.GridHelper(floor, floor * 4, 0xbbbbbb, 0xe4e4e4);
  grid.position.set(center.x, Math.min(lo.y, 0), center.z);
  scene.add(grid);

  const camera = new THREE.PerspectiveCamera(40, 1, 0.01, 1000);
  // The character faces +Z: the camera in front, a little to its left and above, as far as
  // frames the bounds' largest side with a margin.
  const distance = (0.62 * size) / Math.tan((camera.fov * Math.PI) / 360);
  const from = new THREE.Vector3(0.35, 0.2, 1).normalize().multiplyScalar(distance);
  camera.position.copy(center).add(from);
  camera.lookAt(center);
  const controls = renderer ? new THREE.OrbitControls(camera, renderer.domElement) : null;
  if (controls) {
    controls.target.copy(center);
    controls.update();
    controls.addEventListener('change', () => render());
  }

  // Each clip: its bones as line segments and its joints as points, rewritten per frame.
  const figures = clips.map((c) => {
    const colour = new THREE.Color(c.color);
    const bones = new THREE.BufferGeometry();
    bones.setAttribute('position', new THREE.BufferAttribute(new Float32Array(c.bones.length * 6), 3));
    const lines = new THREE.LineSegments(bones, new THREE.LineBasicMaterial({ color: colour }));
    const joints = new THREE.BufferGeometry();
    joints.setAttribute('position', new THREE.BufferAttribute(new Float32Array(c.joints.length * 3), 3));
    const dots = new THREE.Points(joints, new THREE.PointsMaterial({ color: colour, size: 5, sizeAttenuation: false }));
    lines.frustumCulled = false;
    dots.frustumCulled = false;
    scene.add(lines);
    scene.add(dots);
    return { clip: c, bones, joints, frame: -1 };
  });

  if (data.target) {
    const ball = new THREE.Mesh(new THREE.SphereGeometry(0.02, 24, 12),
      new THREE.MeshLambertMaterial({ color: 0xd55e00 }));
    ball.position.set(...data.target);
    scene.add(ball);
  }
  for (const o of data.objects || []) {
    let geometry;
    if (o.kind === 'box') geometry = new THREE.BoxGeometry(2 * o.half[0], 2 * o.half[1], 2 * o.half[2]);
    else if (o.kind === 'sphere') geometry = new THREE.SphereGeometry(o.radius, 32, 16);
    else if (o.kind === 'capsule') geometry = new THREE.CapsuleGeometry(o.radius, 2 * o.half_height, 8, 16);
    else {
      geometry = new THREE.BufferGeometry();
      geometry.setAttribute('position', new THREE.BufferAttribute(new Float32Array(o.vertices), 3));
      geometry.setIndex(o.triangles);
      geometry.computeVertexNormals();
    }
    const mesh = new THREE.Mesh(geometry, new THREE.MeshLambertMaterial({
      color: 0x9aa7b1, transparent: true, opacity: 0.55, side: THREE.DoubleSide,
    }));
    const r = o.rotation; // row-major 3×3
    const m = new THREE.Matrix4().set(r[0], r[1], r[2], o.translation[0],
      r[3], r[4], r[5], o.translation[1], r[6], r[7], r[8], o.translation[2], 0, 0, 0, 1);
    mesh.matrixAutoUpdate = false;
    mesh.matrix.copy(m);
    mesh.name = o.name;
    scene.add(mesh);
  }

  function pose(f) {
    const c = f.clip;
    const k = frameAt(c, time);
    if (k === f.frame) return;
    f.frame = k;
    const base = k * c.joints.length * 3;
    const p = c.positions;
    const j = f.joints.attributes.position.array;
    for (let i = 0; i < c.joints.length * 3; i++) j[i] = p[base + i];
    const b = f.bones.attributes.position.array;
    c.bones.forEach(([from, to], i) => {
      for (let a = 0; a < 3; a++) {
        b[6 * i + a] = p[base + 3 * from + a];
        b[6 * i + 3 + a] = p[base + 3 * to + a];
      }
    });
    f.joints.attributes.position.needsUpdate = true;
    f.bones.attributes.position.needsUpdate = true;
  }

  // ---- the chart -------------------------------------------------------------------------
  const chart = document.getElementById('chart');
  const pen = chart.getContext('2d');
  const top = Math.max(0.1, ...clips.flatMap((c) => c.speed));
  const margin = { left: 52, right: 12, top: 10, bottom: 30 };
  const xOf = (t) => margin.left + (t / Math.max(duration, 1e-9)) * (chart.width - margin.left - margin.right);
  const yOf = (v) => chart.height - margin.bottom - (v / top) * (chart.height - margin.top - margin.bottom);
  // The lines and axes are drawn once per size into a layer; each frame copies it and draws
  // the cursor (redrawing 10,000-point lines every frame cost more than the 3-D view).
  const layer = document.createElement('canvas');
  let layerSize = '';
  function drawChart() {
    const key = chart.width + 'x' + chart.height;
    if (key !== layerSize) {
      layer.width = chart.width;
      layer.height = chart.height;
      drawLines(layer.getContext('2d'));
      layerSize = key;
    }
    if (layerSize !== drawnSize) {
      pen.clearRect(0, 0, chart.width, chart.height);
      pen.drawImage(layer, 0, 0);
      drawnSize = layerSize;
      cursor.style.top = chart.offsetTop + margin.top + 'px';
      cursor.style.height = chart.height - margin.top - margin.bottom + 'px';
    }
    // The cursor is a line over the chart moved by a transform: the chart is not redrawn.
    cursor.style.transform = 'translateX(' + ((xOf(time) * chart.clientWidth) / chart.width).toFixed(1) + 'px)';
  }
  let drawnSize = '';
  const cursor = document.getElementById('cursor');
  function drawLines(pen) {
    const w = chart.width;
    const h = chart.height;
    pen.clearRect(0, 0, w, h);
    pen.font = '12px sans-serif';
    pen.strokeStyle = '#999';
    pen.fillStyle = '#333';
    pen.beginPath();
    pen.moveTo(margin.left, margin.top);
    pen.lineTo(margin.left, h - margin.bottom);
    pen.lineTo(w - margin.right, h - margin.bottom);
    pen.stroke();
    for (let i = 0; i <= 4; i++) {
      const v = (top * i) / 4;
      pen.fillText(v.toFixed(2), 4, yOf(v) + 4);
      const t = (duration * i) / 4;
      pen.textAlign = i === 0 ? 'left' : i === 4 ? 'right' : 'center';
      pen.fillText(t.toFixed(2) + ' s', xOf(t), h - 10);
      pen.textAlign = 'left';
    }
    pen.fillText('hand speed (m/s)', margin.left + 6, margin.top + 10);
    for (const c of clips) {
      pen.strokeStyle = c.color;
      pen.lineWidth = 1.5;
      pen.beginPath();
      c.speed.forEach((v, k) => {
        const x = xOf(k * c.frame_time);
        const y = yOf(v);
        if (k === 0) pen.moveTo(x, y);
        else pen.lineTo(x, y);
      });
      pen.stroke();
    }
  }
  chart.addEventListener('click', (e) => {
    const r = chart.getBoundingClientRect();
    const x = ((e.clientX - r.left) * chart.width) / r.width;
    seek(((x - margin.left) / (chart.width - margin.left - margin.right)) * duration);
  });

  // ---- controls --------------------------------------------------------------------------
  const scrubber = document.getElementById('scrubber');
  scrubber.max = String(duration);
  scrubber.step = String(finest);
  const playButton = document.getElementById('play');
  const clock = document.getElementById('clock');
  scrubber.addEventListener('input', () => seek(Number(scrubber.value)));
  playButton.addEventListener('click', () => {
    playing = !playing;
    if (playing && time >= duration) time = 0;
    render();
  });
  document.getElementById('back').addEventListener('click', () => step(-1));
  document.getElementById('forward').addEventListener('click', () => step(1));
  document.getElementById('speed').addEventListener('change', (e) => {
    speed = Number(e.target.value);
  });
  document.addEventListener('keydown', (e) => {
    if (e.key === ' ') { playing = !playing; e.preventDefault(); render(); }
    if (e.key === 'ArrowLeft') step(-1);
    if (e.key === 'ArrowRight') step(1);
  });
  function step(n) {
    playing = false;
    seek(Math.round(time / finest + n) * finest);
  }
  function seek(t) {
    time = Math.min(Math.max(t, 0), duration);
    render();
  }

  // ---- rendering and the report ----------------------------------------------------------
  function resize() {
    const w = view.clientWidth;
    const h = view.clientHeight;
    if (renderer) {
      renderer.setSize(w, h, false);
    } else {
      canvas.width = w;
      canvas.height = h;
    }
    camera.aspect = w / Math.max(h, 1);
    camera.updateProjectionMatrix();
    if (chart.width !== chart.clientWidth || chart.height !== chart.clientHeight) {
      chart.width = chart.clientWidth;
      chart.height = chart.clientHeight;
      drawnSize = '';
    }
  }
  let first = true;
  let shownAt = -Infinity;
  function render() {
    figures.forEach(pose);
    if (renderer) renderer.render(scene, camera);
    drawChart();
    // The scrubber and the clock at most 10 times a second while playing: each change repaints
    // them, which a software compositor pays for on every frame.
    const now = performance.now();
    if (!playing || now - shownAt > 100) {
      shownAt = now;
      scrubber.value = String(time);
      playButton.textContent = playing ? 'pause' : 'play';
      clock.textContent = time.toFixed(3) + ' s / ' + duration.toFixed(3) + ' s';
    }
    report.time = String(time);
    report.shown = JSON.stringify(figures.map((f) => f.frame));
    // While playing, the rest waits for a pause (it costs more than the drawing for many clips).
    if (playing && !first) return;
    first = false;
    camera.updateMatrixWorld();
    const w = view.clientWidth;
    const h = view.clientHeight;
    // Where each joint is on the screen, read back from the drawn geometry (CSS pixels, top left).
    const screen = figures.map((f) => {
      const a = f.joints.attributes.position.array;
      const out = [];
      for (let i = 0; i < a.length; i += 3) {
        const v = new THREE.Vector3(a[i], a[i + 1], a[i + 2]).project(camera);
        out.push([((v.x + 1) / 2) * w, ((1 - v.y) / 2) * h]);
      }
      return out;
    });
    const viewProjection = new THREE.Matrix4().multiplyMatrices(camera.projectionMatrix, camera.matrixWorldInverse);
    report.screen = JSON.stringify(screen);
    report.camera = JSON.stringify(viewProjection.elements); // column-major, as three.js keeps it
    report.viewport = w + ',' + h;
    const box = canvas.getBoundingClientRect();
    report.canvas = JSON.stringify([box.left, box.top]);
  }

  const intervals = [];
  const work = [];
  let last = null;
  function loop(now) {
    if (last !== null) {
      const dt = (now - last) / 1000;
      intervals.push(dt);
      if (intervals.length > 600) intervals.shift();
      if (playing) {
        time += dt * speed;
        if (time > duration) time = duration > 0 ? time % duration : 0;
      }
    }
    last = now;
    if (playing || intervals.length < 2) {
      const start = performance.now();
      render();
      work.push(performance.now() - start);
      if (work.length > 600) work.shift();
    }
    if (intervals.length % 30 === 0 && intervals.length > 0) {
      const sorted = intervals.slice().sort((a, b) => a - b);
      const mean = intervals.reduce((s, v) => s + v, 0) / intervals.length;
      report.frameMs = (mean * 1000).toFixed(2);
      report.frameMsP95 = (sorted[Math.floor(0.95 * (sorted.length - 1))] * 1000).toFixed(2);
      report.renderedFrames = String(intervals.length);
      // The page's own work per frame (posing, drawing calls, the chart), ms: what is left of
      // a frame is the browser's (compositing; rasterizing, without a GPU).
      report.renderMs = (work.reduce((s, v) => s + v, 0) / Math.max(work.length, 1)).toFixed(3);
    }
    requestAnimationFrame(loop);
  }

  window.addEventListener('resize', () => { resize(); render(); });
  resize();
  render();
  report.clips = String(clips.length);
  report.joints = JSON.stringify(clips.map((c) => c.joints.length));
  report.frames = JSON.stringify(clips.map((c) => c.frames));
  report.labels = JSON.stringify(clips.map((c) => c.label));
  report.three = THREE.REVISION;
  report.ready = '1';
  console.log('kinergy-view: clips=' + clips.length + ' joints=' + report.joints + ' frames=' +
    report.frames + ' shown=' + report.shown + ' time=' + time);
  window.kinergyView = { seek, get time() { return time; }, get playing() { return playing; } };
  requestAnimationFrame(loop);
})();
