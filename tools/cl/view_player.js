// The player of ./course view (tools/cl/view.py inlines it after three.js and
// OrbitControls, and the runs' data as <script id="runK"> (header JSON) and
// <script id="binK"> (trajectory.bin, base64); docs/DESIGN.md §3). The live
// page (tools/cl/live_page.html) inlines it too and draws with its shared
// pieces, window.CLPlayer; the replay below runs only where runs are embedded.
// Plain ES5 with the global THREE: ES modules do not load from file://.
(function () {
  'use strict';

  // Blue (compressed) through grey (0) to red (stretched), t in [-1, 1].
  function strainColour(t, out, i) {
    t = Math.max(-1, Math.min(1, t));
    var grey = 0.55;
    if (t >= 0) { out[i] = grey + (1 - grey) * t; out[i + 1] = grey * (1 - t); out[i + 2] = grey * (1 - t); }
    else { t = -t; out[i] = grey * (1 - t); out[i + 1] = grey * (1 - t) + 0.2 * t; out[i + 2] = grey + (1 - grey) * t; }
  }

  // One run's three.js scene: springs coloured by strain, particles, pinned
  // particles marked (room for `pinnedRoom`), triangles shaded.
  // mesh = {particles: n, springs: [i, j, ...], triangles: [i, j, k, ...]}.
  function makeRunScene(mesh, pinnedRoom) {
    var n = mesh.particles, m = mesh.springs.length / 2;
    var scene = new THREE.Scene();
    scene.add(new THREE.AmbientLight(0xffffff, 0.55));
    var light = new THREE.DirectionalLight(0xffffff, 0.6);
    light.position.set(1, 2, 3);
    scene.add(light);
    var lines = new THREE.BufferGeometry();
    lines.setAttribute('position', new THREE.BufferAttribute(new Float32Array(6 * m), 3));
    lines.setAttribute('color', new THREE.BufferAttribute(new Float32Array(6 * m), 3));
    scene.add(new THREE.LineSegments(lines, new THREE.LineBasicMaterial({ vertexColors: true })));
    var points = new THREE.BufferGeometry();
    points.setAttribute('position', new THREE.BufferAttribute(new Float32Array(3 * n), 3));
    var pointSize = n > 2000 ? 1.5 : 3;
    scene.add(new THREE.Points(points, new THREE.PointsMaterial({ color: 0x333333, size: pointSize, sizeAttenuation: false })));
    var pinned = new THREE.BufferGeometry();
    pinned.setAttribute('position', new THREE.BufferAttribute(new Float32Array(3 * Math.max(pinnedRoom, 1)), 3));
    pinned.setDrawRange(0, 0);
    scene.add(new THREE.Points(pinned, new THREE.PointsMaterial({ color: 0xd08000, size: 9, sizeAttenuation: false })));
    var surface = null;
    if (mesh.triangles.length) {
      surface = new THREE.BufferGeometry();
      surface.setAttribute('position', new THREE.BufferAttribute(new Float32Array(3 * n), 3));
      surface.setIndex(mesh.triangles);
      scene.add(new THREE.Mesh(surface, new THREE.MeshLambertMaterial({
        color: 0x8fb0d0, side: THREE.DoubleSide, transparent: true, opacity: 0.55,
        polygonOffset: true, polygonOffsetFactor: 1, polygonOffsetUnits: 1 })));
    }
    return { scene: scene, lines: lines, points: points, pinnedPoints: pinned, surface: surface };
  }

  // One frame into a run's scene (makeRunScene's parts): positions x (3n, m),
  // signed strains (one per spring) coloured over [−scale, scale], and the
  // particles of pinnedList marked.
  function setRunFrame(run, mesh, x, strain, scale, pinnedList) {
    var m = mesh.springs.length / 2;
    var lp = run.lines.attributes.position.array, lc = run.lines.attributes.color.array;
    for (var e = 0; e < m; ++e) {
      var i = mesh.springs[2 * e], j = mesh.springs[2 * e + 1];
      for (var a = 0; a < 3; ++a) { lp[6 * e + a] = x[3 * i + a]; lp[6 * e + 3 + a] = x[3 * j + a]; }
      strainColour(strain[e] / scale, lc, 6 * e);
      lc[6 * e + 3] = lc[6 * e]; lc[6 * e + 4] = lc[6 * e + 1]; lc[6 * e + 5] = lc[6 * e + 2];
    }
    run.lines.attributes.position.needsUpdate = true;
    run.lines.attributes.color.needsUpdate = true;
    run.points.attributes.position.array.set(x);
    run.points.attributes.position.needsUpdate = true;
    var pp = run.pinnedPoints.attributes.position.array;
    var marked = Math.min(pinnedList.length, pp.length / 3);
    for (var q = 0; q < marked; ++q) { for (var b = 0; b < 3; ++b) pp[3 * q + b] = x[3 * pinnedList[q] + b]; }
    run.pinnedPoints.setDrawRange(0, marked);
    run.pinnedPoints.attributes.position.needsUpdate = true;
    if (run.surface) {
      run.surface.attributes.position.array.set(x);
      run.surface.attributes.position.needsUpdate = true;
      run.surface.computeVertexNormals();
    }
  }

  // A scene's colliders (lab 14; the header's or the live hello's "colliders")
  // into a three.js scene: spheres and capsules shaded, drawn 1 % thinner so
  // that cloth lying on them (its springs are chords, just under the surface)
  // stays in sight; a plane as a square of half-side `extent` (m) around the
  // point of it nearest `centre` (the cloth's box centre). Returns how many.
  function addColliders(scene, colliders, centre, extent) {
    if (!colliders || !colliders.length) return 0;
    var solid = new THREE.MeshLambertMaterial({ color: 0xc8b89a, transparent: true, opacity: 0.8 });
    var flat = new THREE.MeshLambertMaterial({ color: 0xa8a8a0, side: THREE.DoubleSide, transparent: true, opacity: 0.45 });
    function v(p) { return new THREE.Vector3(p[0], p[1], p[2]); }
    function ball(at, r) {
      var mesh = new THREE.Mesh(new THREE.SphereGeometry(0.99 * r, 32, 16), solid);
      mesh.position.copy(at);
      scene.add(mesh);
    }
    colliders.forEach(function (c) {
      if (c.type === 'sphere') ball(v(c.centre), c.radius);
      if (c.type === 'capsule') {
        var a = v(c.a), b = v(c.b), axis = b.clone().sub(a), length = axis.length();
        ball(a, c.radius);
        ball(b, c.radius);
        if (length > 0) {
          var tube = new THREE.Mesh(new THREE.CylinderGeometry(0.99 * c.radius, 0.99 * c.radius, length, 32, 1, true), solid);
          tube.position.copy(a.clone().add(b).multiplyScalar(0.5));
          tube.quaternion.setFromUnitVectors(new THREE.Vector3(0, 1, 0), axis.normalize());
          scene.add(tube);
        }
      }
      if (c.type === 'plane') {
        var n = v(c.normal).normalize(), o = v(centre);
        var foot = o.sub(n.clone().multiplyScalar(o.clone().sub(v(c.point)).dot(n)));
        var square = new THREE.Mesh(new THREE.PlaneGeometry(2 * extent, 2 * extent), flat);
        square.position.copy(foot);
        square.quaternion.setFromUnitVectors(new THREE.Vector3(0, 0, 1), n);
        scene.add(square);
      }
    });
    return colliders.length;
  }

  window.CLPlayer = { strainColour: strainColour, makeRunScene: makeRunScene, setRunFrame: setRunFrame,
                      addColliders: addColliders };
  if (!document.getElementById('run0')) return;  // the live page: no replay

  var body = document.body;
  var runs = [];
  for (var r = 0; document.getElementById('run' + r); ++r) {
    var header = JSON.parse(document.getElementById('run' + r).textContent);
    var text = atob(document.getElementById('bin' + r).textContent.trim());
    var bytes = new Uint8Array(text.length);
    for (var b = 0; b < text.length; ++b) bytes[b] = text.charCodeAt(b);
    runs.push({ header: header, bytes: bytes });
  }

  // Frame k of a run: positions (Float32Array, 3n, m) and strains (Float32Array, m).
  function decode(run, k) {
    var h = run.header, n = h.particles, m = h.springs.length / 2, f = h.frames[k];
    var offset = k * h.frame_bytes;
    var levels = new Uint16Array(run.bytes.buffer, offset, 3 * n);  // little-endian, as every browser is
    var strains = new Int8Array(run.bytes.buffer, offset + 6 * n, m);
    var x = new Float64Array(3 * n), s = new Float32Array(m);
    for (var p = 0; p < n; ++p) {
      for (var a = 0; a < 3; ++a) x[3 * p + a] = f.box_min[a] + levels[3 * p + a] * f.step[a];
    }
    for (var e = 0; e < m; ++e) s[e] = strains[e] * f.strain_scale / 127;
    return { x: x, strain: s };
  }

  var renderer = new THREE.WebGLRenderer({ antialias: true, preserveDrawingBuffer: true });
  renderer.setPixelRatio(window.devicePixelRatio || 1);
  renderer.setClearColor(0xf4f4f0);
  renderer.setScissorTest(true);
  body.insertBefore(renderer.domElement, body.firstChild);

  // One scene per run: springs coloured by strain, triangles shaded, pinned marked.
  var lo = [Infinity, Infinity, Infinity], hi = [-Infinity, -Infinity, -Infinity];
  var runScale = 0;
  runs.forEach(function (run) {
    var h = run.header;
    [0, h.frames.length - 1].forEach(function (k) {
      var f = h.frames[k];
      for (var a = 0; a < 3; ++a) {
        lo[a] = Math.min(lo[a], f.box_min[a]);
        hi[a] = Math.max(hi[a], f.box_min[a] + 65535 * f.step[a]);
      }
    });
    h.frames.forEach(function (f) { runScale = Math.max(runScale, f.strain_scale); });
    var parts = makeRunScene(h, h.pinned.length);
    var first = h.frames[0], box = [0, 1, 2].map(function (a) { return 65535 * first.step[a]; });
    run.colliders = addColliders(parts.scene, h.colliders, [0, 1, 2].map(function (a) { return first.box_min[a] + box[a] / 2; }),
                                 Math.max(box[0], box[1], box[2], 1e-3));
    run.scene = parts.scene;
    run.lines = parts.lines;
    run.points = parts.points;
    run.pinnedPoints = parts.pinnedPoints;
    run.surface = parts.surface;
  });

  var camera = new THREE.PerspectiveCamera(40, 1, 1e-3, 1e4);
  var centre = new THREE.Vector3((lo[0] + hi[0]) / 2, (lo[1] + hi[1]) / 2, (lo[2] + hi[2]) / 2);
  var size = Math.max(hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2], 1e-3);
  camera.position.set(centre.x + 0.6 * size, centre.y + 0.35 * size, centre.z + 2.2 * size);
  camera.near = size * 1e-3;
  camera.far = size * 100;
  var controls = new THREE.OrbitControls(camera, renderer.domElement);
  controls.target.copy(centre);
  controls.update();

  // The clock: the frames of the run with the most; every run shows its last
  // frame at or before the clock's time.
  var master = 0;
  runs.forEach(function (run, i) { if (run.header.frames.length > runs[master].header.frames.length) master = i; });
  var clockFrames = runs[master].header.frames;
  function frameAt(run, time) {
    var frames = run.header.frames, k = 0;
    while (k + 1 < frames.length && frames[k + 1].time <= time + 1e-12) ++k;
    return k;
  }

  var slider = document.getElementById('slider');
  slider.max = String(clockFrames.length - 1);
  var params = new URLSearchParams(window.location.search);
  var shown = Math.max(0, Math.min(clockFrames.length - 1, parseInt(params.get('frame') || '0', 10) || 0));
  var playing = false, clockTime = clockFrames[shown].time, last = null;

  function fmt(v, digits) { return v === null || v === undefined ? '–' : Number(v).toPrecision(digits || 4); }

  function show(index) {
    shown = index;
    slider.value = String(index);
    var time = clockFrames[index].time;
    var scale = document.getElementById('scale').value;
    var samples = [], hud = [];
    runs.forEach(function (run, r) {
      var h = run.header, n = h.particles, m = h.springs.length / 2;
      var k = frameAt(run, time), f = h.frames[k], d = decode(run, k);
      var s = Math.max(scaleOf(scale, [f]), 1e-12);
      setRunFrame(run, h, d.x, d.strain, s, h.pinned);
      [0, Math.floor(n / 2), n - 1].forEach(function (p) {
        if (p >= 0) samples.push([r, p, d.x[3 * p], d.x[3 * p + 1], d.x[3 * p + 2]]);
      });
      // A sweep lab's frame is its sweep: no time of its own to show.
      var seconds = h.time_unit === 's';
      var when = seconds ? ' · t = ' + fmt(f.time) + ' s' : '';
      var status = f.status && f.status !== 'ok' ? '  ' + f.status : '';
      hud.push('<div class="run"><b>' + esc(h.lab) + '</b> · ' + esc(h.scene) + ' · ' + esc(h.method) +
               '\n' + (seconds ? 'frame ' : h.time_unit + ' ') + f.frame + ' (' + (k + 1) + '/' + h.frames.length + ')' + when +
               ' · max strain ' + fmt(f.max_strain, 3) +
               (h.energy_name ? ' · ' + esc(h.energy_name) + ' ' + fmt(f.energy, 6) + ' J' : '') + esc(status) +
               (h.stopped && k === h.frames.length - 1 ? '\nstopped at frame ' + h.stopped.frame + ': ' + esc(h.stopped.status) : '') +
               '\n<span class="command">' + esc(h.command) + ' · ' + n + ' particles, ' + m + ' springs' +
               (h.triangles.length ? ', ' + h.triangles.length / 3 + ' triangles' : '') +
               ' · positions ±' + fmt(h.max_position_error, 2) + ' m</span></div>');
      run.frameShown = k;
    });
    document.getElementById('hud').innerHTML = hud.join('');
    document.getElementById('counter').textContent = (index + 1) + ' / ' + clockFrames.length;
    var barScale = scaleOf(scale, runs.map(function (run) { return run.header.frames[run.frameShown]; }));
    document.getElementById('bar-low').textContent = '−' + fmt(barScale, 2);
    document.getElementById('bar-high').textContent = '+' + fmt(barScale, 2);
    body.setAttribute('data-frame', String(index));
    body.setAttribute('data-sample', JSON.stringify(samples));
    draw();
  }

  // The colour scale: the largest |strain| of the runs, of the frames shown, or a fixed one.
  function scaleOf(choice, shownFrames) {
    if (choice === 'run') return runScale;
    if (choice === 'frame') return shownFrames.reduce(function (a, f) { return Math.max(a, f.strain_scale); }, 0);
    return parseFloat(choice);
  }

  function esc(text) {
    return String(text).replace(/&/g, '&amp;').replace(/</g, '&lt;').replace(/>/g, '&gt;');
  }

  function draw() {
    var width = window.innerWidth, height = window.innerHeight;
    renderer.setSize(width, height);
    var part = Math.floor(width / runs.length);
    camera.aspect = part / height;
    camera.updateProjectionMatrix();
    runs.forEach(function (run, r) {
      renderer.setViewport(r * part, 0, part, height);
      renderer.setScissor(r * part, 0, part, height);
      renderer.render(run.scene, camera);
    });
  }

  (function colourBar() {
    var canvas = document.getElementById('bar-canvas'), context = canvas.getContext('2d');
    var rgb = [0, 0, 0];
    for (var x = 0; x < canvas.width; ++x) {
      strainColour(2 * x / (canvas.width - 1) - 1, rgb, 0);
      context.fillStyle = 'rgb(' + rgb.map(function (c) { return Math.round(255 * c); }).join(',') + ')';
      context.fillRect(x, 0, 1, canvas.height);
    }
  })();

  function step(by) {
    var next = shown + by;
    if (next >= clockFrames.length) next = document.getElementById('loop').checked ? 0 : clockFrames.length - 1;
    if (next < 0) next = clockFrames.length - 1;
    clockTime = clockFrames[next].time;
    show(next);
  }

  function tick(now) {
    if (playing && last !== null) {
      var speed = parseFloat(document.getElementById('speed').value);
      // Real time for seconds; ten sweeps a second for the sweep labs.
      var rate = runs[master].header.time_unit === 's' ? 1 : 10;
      clockTime += (now - last) / 1000 * rate * speed;
      var end = clockFrames[clockFrames.length - 1].time;
      if (clockTime > end) {
        if (document.getElementById('loop').checked) clockTime = clockFrames[0].time;
        else { clockTime = end; setPlaying(false); }
      }
      var k = frameAt(runs[master], clockTime);
      if (k !== shown) show(k);
    }
    last = now;
    requestAnimationFrame(tick);
  }

  function setPlaying(on) {
    playing = on;
    document.getElementById('play').textContent = on ? 'pause' : 'play';
  }

  document.getElementById('play').onclick = function () {
    if (!playing && shown === clockFrames.length - 1) { clockTime = clockFrames[0].time; show(0); }
    setPlaying(!playing);
  };
  document.getElementById('back').onclick = function () { setPlaying(false); step(-1); };
  document.getElementById('forward').onclick = function () { setPlaying(false); step(1); };
  slider.oninput = function () { setPlaying(false); clockTime = clockFrames[+slider.value].time; show(+slider.value); };
  document.getElementById('scale').onchange = function () { show(shown); };
  window.addEventListener('keydown', function (e) {
    if (e.key === ' ') { document.getElementById('play').onclick(); e.preventDefault(); }
    if (e.key === 'ArrowLeft') document.getElementById('back').onclick();
    if (e.key === 'ArrowRight') document.getElementById('forward').onclick();
  });
  // The controls that pass (or touch) the window's edge, by id, in
  // data-outside: a layout that works at one width can clip at another (the
  // scale selector once ran to the right edge at 1200 px). The browser check reads it.
  function markOutside() {
    var outside = ['hud', 'bar', 'scale', 'controls', 'speed', 'loop'].filter(function (id) {
      var box = document.getElementById(id).getBoundingClientRect();
      return box.left < 2 || box.top < 2 || box.right > window.innerWidth - 2 || box.bottom > window.innerHeight - 2;
    });
    body.setAttribute('data-outside', outside.join(','));
  }
  controls.addEventListener('change', draw);
  window.addEventListener('resize', function () { draw(); markOutside(); });

  function list(f) { return runs.map(f).join(','); }
  body.setAttribute('data-runs', String(runs.length));
  body.setAttribute('data-frames', list(function (run) { return run.header.frames.length; }));
  body.setAttribute('data-particles', list(function (run) { return run.header.particles; }));
  body.setAttribute('data-springs', list(function (run) { return run.header.springs.length / 2; }));
  body.setAttribute('data-colliders', list(function (run) { return run.colliders; }));
  show(shown);
  markOutside();
  // ms from the start of the page's navigation to its first frame drawn (the load-time benchmark).
  body.setAttribute('data-ready-ms', String(Math.round(performance.now())));
  body.setAttribute('data-ready', '1');
  requestAnimationFrame(tick);
})();
