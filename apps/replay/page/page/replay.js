// kelp replay: the 3-D view of one run, from window.KELP_REPLAY_DATA (the replay data, format
// "kelp-replay", documented in docs/replay.md: version 1 for the tethered pair, version 2 for any
// fleet of vehicles, point masses, anchors and tethers) with three.js (window.THREE).
//
// Frames: the data is NED (north, east, down) with ZYX roll/pitch/yaw (Fossen, "Handbook of
// Marine Craft Hydrodynamics and Motion Control", 2nd ed. 2021, eq. 2.18). three.js is y-up; the
// scene's axes are x = north, y = up = -down, z = east (a right-handed pair, so rotations map by
// conjugation). A body's axes (forward, starboard, down) map the same way: the models below are
// built with the bow along +x, starboard along +z and up along +y.
//
// window.kelpReplay is the page's interface for tests and scripts; its members are listed where
// it is defined, at the end of this file.
(function () {
  'use strict';

  // ---------------------------------------------------------------------------------------------
  // Pure functions of the data (no three.js)

  /// Surface elevation ζ(x, y, t) [m, up] at NED north x, east y [m] and time t [s], exactly as
  /// kelp computes it (kelp::environment::Waves::elevation times Environment's start-up ramp):
  ///   ζ = r(t) Σ_j a_j cos(k_j (x cos β_j + y sin β_j) − ω_j t + φ_j),
  ///   r(t) = ½ (1 − cos(π t / T)) on [0, T), 0 before 0, 1 from T on (1 always when T = 0),
  /// with k_j cos β_j and k_j sin β_j formed first, as kelp does, in double precision.
  function makeWaves(waves) {
    const c = (waves && waves.components) || {};
    const a = Float64Array.from(c.amplitude || []);
    const w = Float64Array.from(c.omega || []);
    const phi = Float64Array.from(c.phase || []);
    const kx = new Float64Array(a.length);
    const ky = new Float64Array(a.length);
    for (let j = 0; j < a.length; ++j) {
      kx[j] = c.k[j] * Math.cos(c.direction[j]);
      ky[j] = c.k[j] * Math.sin(c.direction[j]);
    }
    const ramp = (waves && waves.ramp) || 0;
    const tp = new Float64Array(a.length); // time phases φ_j − ω_j t of the last prepare()
    function rampFactor(t) {
      if (!(ramp > 0) || t >= ramp) return 1;
      if (t <= 0) return 0;
      return 0.5 * (1 - Math.cos((Math.PI * t) / ramp));
    }
    function elevation(x, y, t) {
      let z = 0;
      for (let j = 0; j < a.length; ++j) z += a[j] * Math.cos(kx[j] * x + ky[j] * y + (phi[j] - w[j] * t));
      return rampFactor(t) * z;
    }
    // The same sum for many points at one time: prepare(t) once, then at(x, y).
    let r = 1;
    function prepare(t) {
      for (let j = 0; j < a.length; ++j) tp[j] = phi[j] - w[j] * t;
      r = rampFactor(t);
    }
    function at(x, y) {
      let z = 0;
      for (let j = 0; j < a.length; ++j) z += a[j] * Math.cos(kx[j] * x + ky[j] * y + tp[j]);
      return r * z;
    }
    /// The elevation on a regular grid n_i = n0 + i h, e_j = e0 + j h (i, j < count) at time t,
    /// into out[i * count + j]: the same sum with each cosine split as Re(e^{i kx n} e^{i ky e}
    /// e^{i (φ − ω t)}), so a frame needs 2 count cosines per component instead of count².
    /// (Equal to elevation() to rounding, ~1e-15 m; the exact path is elevation().)
    let rowRe = new Float64Array(0), rowIm = rowRe, colC = rowRe, colS = rowRe;
    function grid(n0, e0, h, count, t, out) {
      const J = a.length;
      if (rowRe.length !== count * J) {
        rowRe = new Float64Array(count * J);
        rowIm = new Float64Array(count * J);
        colC = new Float64Array(count * J);
        colS = new Float64Array(count * J);
      }
      const rt = rampFactor(t);
      for (let i = 0; i < count; ++i) {
        const n = n0 + i * h, e = e0 + i * h;
        for (let j = 0; j < J; ++j) {
          const th = kx[j] * n + (phi[j] - w[j] * t);
          rowRe[i * J + j] = rt * a[j] * Math.cos(th);
          rowIm[i * J + j] = rt * a[j] * Math.sin(th);
          colC[i * J + j] = Math.cos(ky[j] * e);
          colS[i * J + j] = Math.sin(ky[j] * e);
        }
      }
      for (let i = 0; i < count; ++i)
        for (let q = 0; q < count; ++q) {
          let z = 0;
          for (let j = 0, r = i * J, c = q * J; j < J; ++j) z += rowRe[r + j] * colC[c + j] - rowIm[r + j] * colS[c + j];
          out[i * count + q] = z;
        }
    }
    return { elevation, prepare, at, grid, count: a.length };
  }

  /// Index i of the sample interval [t_i, t_{i+1}] holding t, and the fraction u ∈ [0, 1] of t
  /// in it (clamped to the first and last samples).
  function locate(ts, t) {
    const n = ts.length;
    if (n === 0) return { i: 0, u: 0 };
    if (!(t > ts[0])) return { i: 0, u: 0 };
    if (t >= ts[n - 1]) return { i: n - 1, u: 0 };
    let lo = 0;
    let hi = n - 1; // ts[lo] <= t < ts[hi]
    while (hi - lo > 1) {
      const mid = (lo + hi) >> 1;
      if (ts[mid] <= t) lo = mid;
      else hi = mid;
    }
    const span = ts[hi] - ts[lo];
    return { i: lo, u: span > 0 ? (t - ts[lo]) / span : 0 };
  }

  const num = (v) => (v === null || v === undefined ? NaN : v);
  const lerp = (a, b, u) => a + (b - a) * u;
  function lerpAt(arr, loc) {
    const a = num(arr[loc.i]);
    if (loc.u === 0 || loc.i + 1 >= arr.length) return a;
    return lerp(a, num(arr[loc.i + 1]), loc.u);
  }
  function lerpAngle(arr, loc) {
    const a = num(arr[loc.i]);
    if (loc.u === 0 || loc.i + 1 >= arr.length) return a;
    let d = num(arr[loc.i + 1]) - a;
    d -= 2 * Math.PI * Math.round(d / (2 * Math.PI)); // the short way round
    return a + d * loc.u;
  }
  function lerpRow(rows, loc) {
    const a = rows[loc.i] || [];
    const b = loc.u === 0 ? a : rows[loc.i + 1] || a;
    return a.map((v, k) => lerp(num(v), num(b[k]), loc.u));
  }

  /// A vehicle's pose at t: NED position and roll, pitch, yaw, linear between log samples (the
  /// angles the short way round).
  function pose(series, key, loc) {
    return poseOf(series[key], loc);
  }
  /// The same for a body's own arrays s.n, s.e, s.d, s.roll, s.pitch, s.yaw (a fleet's vehicle).
  function poseOf(s, loc) {
    return {
      n: lerpAt(s.n, loc), e: lerpAt(s.e, loc), d: lerpAt(s.d, loc),
      roll: lerpAngle(s.roll, loc), pitch: lerpAngle(s.pitch, loc), yaw: lerpAngle(s.yaw, loc),
    };
  }

  /// The tether at t: node positions (flat n, e, d) and segment tensions, linear between node
  /// samples of the same node count; across a change of count (the winch adds or removes nodes)
  /// the earlier sample holds until the next one.
  function tetherAt(nodes, t) {
    if (!nodes || !nodes.t || nodes.t.length === 0) return { position: [], tension: [] };
    const loc = locate(nodes.t, t);
    const p0 = nodes.position[loc.i];
    const tension = nodes.tension || []; // a fleet's lines log no segment tension
    const t0 = tension[loc.i] || [];
    const p1 = nodes.position[loc.i + 1];
    if (loc.u === 0 || !p1 || p1.length !== p0.length) return { position: p0.slice(), tension: t0.slice() };
    const t1 = tension[loc.i + 1] || t0;
    return {
      position: p0.map((v, k) => lerp(v, p1[k], loc.u)),
      tension: t0.map((v, k) => lerp(v, t1[k] === undefined ? v : t1[k], loc.u)),
    };
  }

  /// Rotation matrix body → NED, R = Rz(ψ) Ry(θ) Rx(φ) (Fossen 2021, eq. 2.18), row-major.
  function rotationNED(roll, pitch, yaw) {
    const cf = Math.cos(roll), sf = Math.sin(roll);
    const ct = Math.cos(pitch), st = Math.sin(pitch);
    const cp = Math.cos(yaw), sp = Math.sin(yaw);
    return [
      [cp * ct, -sp * cf + cp * st * sf, sp * sf + cp * cf * st],
      [sp * ct, cp * cf + sf * st * sp, -cp * sf + st * sp * cf],
      [-st, ct * sf, ct * cf],
    ];
  }
  // M: NED → scene, (n, e, d) ↦ (n, −d, e).
  const M = [[1, 0, 0], [0, 0, -1], [0, 1, 0]];
  function mul3(A, B) {
    const C = [[0, 0, 0], [0, 0, 0], [0, 0, 0]];
    for (let i = 0; i < 3; ++i)
      for (let j = 0; j < 3; ++j) C[i][j] = A[i][0] * B[0][j] + A[i][1] * B[1][j] + A[i][2] * B[2][j];
    return C;
  }
  const MT = [[1, 0, 0], [0, 0, 1], [0, -1, 0]];
  /// The rotation in scene axes, M R Mᵀ (row-major).
  function rotationScene(roll, pitch, yaw) {
    return mul3(mul3(M, rotationNED(roll, pitch, yaw)), MT);
  }

  // Tension colour map: ColorBrewer's five-class YlOrRd (Harrower & Brewer, "ColorBrewer.org",
  // The Cartographic Journal 40(1), 2003; pale yellow to dark red, all of which stand out against
  // the sea), interpolated linearly in sRGB. The top stop is the colour at and above the scale's
  // maximum.
  const STOPS = [[0xff, 0xff, 0xb2], [0xfe, 0xcc, 0x5c], [0xfd, 0x8d, 0x3c], [0xf0, 0x3b, 0x20], [0xbd, 0x00, 0x26]];
  function colourAt(u) {
    if (!(u > 0)) u = 0; // NaN: the bottom
    if (u > 1) u = 1;
    const x = u * (STOPS.length - 1);
    const i = Math.min(Math.floor(x), STOPS.length - 2);
    const f = x - i;
    return STOPS[i].map((c, k) => Math.round(c + (STOPS[i + 1][k] - c) * f));
  }
  const hex = (rgb) => '#' + rgb.map((c) => c.toString(16).padStart(2, '0')).join('');

  // ---------------------------------------------------------------------------------------------
  // The page

  function showMessage(text) {
    const el = document.getElementById('message');
    el.textContent = text;
    el.hidden = false;
  }

  function init() {
    const data = window.KELP_REPLAY_DATA;
    const THREE = window.THREE;
    if (!THREE) return showMessage('three.js is missing from this page (a build problem).');
    if (!data || data.format !== 'kelp-replay')
      return showMessage('This page holds no kelp replay data (it is the template: kelp-replay DIR makes a replay of a run).');
    if (data.version !== 1 && data.version !== 2)
      return showMessage(`Replay data version ${data.version}; this page reads versions 1 (the pair) and 2 (a fleet).`);
    // Version 2: any fleet (data.vehicles, point_masses, anchors, tethers) instead of the pair's
    // boat, ROV and tether; the sea, seabed, obstacles, legend and controls are the same.
    const fleet = data.version === 2;

    const series = data.series;
    const nodes = data.nodes || { t: [], position: [], tension: [] };
    const waves = makeWaves(data.waves);
    const duration = data.duration || (series.t.length ? series.t[series.t.length - 1] : 0);
    let tmin = 0;
    if (series.t.length) tmin = Math.min(0, series.t[0]);
    const scaleMin = (data.tension_scale && data.tension_scale.min) || 0;
    let scaleMax = data.tension_scale && data.tension_scale.max;
    if (!(scaleMax > scaleMin)) scaleMax = scaleMin + 1;
    const tensionColour = (T) => colourAt((T - scaleMin) / (scaleMax - scaleMin));

    document.title = `kelp replay: ${data.title || data.source || 'run'}`;
    document.getElementById('title').textContent = data.title || data.source || 'kelp run';

    // Query: ?t=SECONDS, ?paused=1, ?speed=X, ?camera=follow|underwater|orbit, ?sea=N (grid),
    // ?aa=0|1 (antialiasing), ?playres=R (pixel ratio while playing; below), ?focus=NAME (a
    // fleet's vehicle or point mass the underwater camera follows).
    const query = new URLSearchParams(window.location.search);
    const qt = parseFloat(query.get('t'));
    let time = Number.isFinite(qt) ? Math.min(Math.max(qt, tmin), duration) : tmin;
    let playing = !(query.get('paused') === '1' || query.get('paused') === 'true');
    let speed = parseFloat(query.get('speed'));
    if (!(speed >= 0.25 && speed <= 16)) speed = 1;
    let cameraMode = ['follow', 'underwater', 'orbit'].includes(query.get('camera')) ? query.get('camera') : 'follow';
    const seaGrid = Math.min(Math.max(parseInt(query.get('sea'), 10) || 56, 8), 256);

    // Renderer
    const view = document.getElementById('view');
    // Software WebGL (SwiftShader, llvmpipe) draws every multisample: no antialiasing there.
    const software = (() => {
      try {
        const gl = document.createElement('canvas').getContext('webgl2') || document.createElement('canvas').getContext('webgl');
        const ext = gl && gl.getExtension('WEBGL_debug_renderer_info');
        const name = ext ? gl.getParameter(ext.UNMASKED_RENDERER_WEBGL) : '';
        const lose = gl && gl.getExtension('WEBGL_lose_context');
        if (lose) lose.loseContext();
        return /swiftshader|llvmpipe|softpipe|software/i.test(String(name));
      } catch (e) {
        return false;
      }
    })();
    const antialias = query.get('aa') === '1' || (query.get('aa') !== '0' && !software);
    let renderer;
    try {
      renderer = new THREE.WebGLRenderer({ antialias, preserveDrawingBuffer: true, powerPreference: 'high-performance' });
    } catch (e) {
      return showMessage(`WebGL is not available in this browser (${e.message}).`);
    }
    // Pixels per CSS pixel: paused, the screen's (at most 2; 1 in software WebGL); playing in
    // software WebGL, fewer (?playres=, default 0.6), since filling pixels is most of a frame's
    // cost there; pausing draws the frame again at full resolution.
    const fullRatio = software ? 1 : Math.min(window.devicePixelRatio || 1, 2);
    const qr = parseFloat(query.get('playres'));
    const playRatio = qr > 0 && qr <= 2 ? qr : software ? 0.6 : fullRatio;
    renderer.setPixelRatio(fullRatio);
    view.appendChild(renderer.domElement);
    const scene = new THREE.Scene();
    const camera = new THREE.PerspectiveCamera(55, 1, 0.05, 3000);
    const skyColour = new THREE.Color(0x9ec9e2);
    const deepColour = new THREE.Color(0x0d3b55);
    scene.background = skyColour.clone();
    scene.fog = new THREE.Fog(skyColour.clone(), 150, 900);
    scene.add(new THREE.HemisphereLight(0xdfefff, 0x29465a, 1.6));
    const sun = new THREE.DirectionalLight(0xffffff, 1.8);
    sun.position.set(-40, 80, 30);
    scene.add(sun);

    const toScene = (n, e, d) => new THREE.Vector3(n, -d, e);
    const setPose = (obj, p) => {
      const R = rotationScene(p.roll, p.pitch, p.yaw);
      obj.matrix.set(
        R[0][0], R[0][1], R[0][2], p.n,
        R[1][0], R[1][1], R[1][2], -p.d,
        R[2][0], R[2][1], R[2][2], p.e,
        0, 0, 0, 1);
      obj.matrixWorldNeedsUpdate = true;
    };

    // -- models (low poly; sizes from Blue Robotics' published dimensions) --
    const mat = (colour, extra) => new THREE.MeshLambertMaterial(Object.assign({ color: colour, flatShading: true }, extra || {}));
    function prism(len, radius, sides, material) { // along +x, centred
      const g = new THREE.CylinderGeometry(radius, radius, len, sides, 1);
      g.rotateZ(Math.PI / 2);
      return new THREE.Mesh(g, material);
    }
    function place(mesh, x, y, z) {
      mesh.position.set(x, y, z);
      return mesh;
    }

    // BlueBoat: a catamaran 1.2 m long and 1.0 m wide (Blue Robotics, BlueBoat technical
    // details): two hulls with pointed bows, a deck between them, the electronics box, a GNSS
    // mast, and a thruster under each stern.
    function makeBoat() {
      const g = new THREE.Group();
      const hullMat = mat(0x2b3440);
      const stripe = mat(0x1e88e5);
      for (const side of [-1, 1]) {
        const z = side * 0.39;
        const hull = prism(0.92, 0.1, 6, hullMat);
        hull.scale.set(1, 1.2, 1);
        g.add(place(hull, -0.1, -0.03, z));
        const bow = new THREE.Mesh(new THREE.ConeGeometry(0.1, 0.3, 6), hullMat);
        bow.rotation.z = -Math.PI / 2;
        bow.scale.set(1.2, 1, 1);
        g.add(place(bow, 0.51, -0.03, z));
        g.add(place(new THREE.Mesh(new THREE.BoxGeometry(0.86, 0.03, 0.21), stripe), -0.1, 0.08, z));
        const thr = prism(0.12, 0.045, 8, mat(0x111111));
        g.add(place(thr, -0.5, -0.17, z));
      }
      g.add(place(new THREE.Mesh(new THREE.BoxGeometry(0.62, 0.04, 0.72), mat(0x1e88e5)), -0.08, 0.11, 0));
      g.add(place(new THREE.Mesh(new THREE.BoxGeometry(0.36, 0.12, 0.3), mat(0xe8eef2)), -0.1, 0.19, 0));
      g.add(place(new THREE.Mesh(new THREE.CylinderGeometry(0.012, 0.012, 0.45, 5), mat(0x999999)), -0.3, 0.36, 0));
      g.add(place(new THREE.Mesh(new THREE.CylinderGeometry(0.05, 0.05, 0.03, 8), mat(0xf4f4f4)), -0.3, 0.59, 0));
      return g;
    }

    // BlueROV2 Heavy: 457 × 575 × 254 mm (Blue Robotics, BlueROV2 Heavy Retrofit Kit): two side
    // panels joined by cross bars, the buoyancy block on top, the electronics tube, four vectored
    // horizontal thrusters at the corners and four vertical ones. Each thruster's ring is coloured
    // by its command (orange forward, blue reverse).
    function makeRov() {
      const g = new THREE.Group();
      const frameMat = mat(0x202428);
      for (const side of [-1, 1]) {
        g.add(place(new THREE.Mesh(new THREE.BoxGeometry(0.46, 0.25, 0.014), frameMat), 0, 0, side * 0.17));
      }
      for (const x of [-0.2, 0.2]) g.add(place(new THREE.Mesh(new THREE.BoxGeometry(0.03, 0.03, 0.34), frameMat), x, -0.11, 0));
      g.add(place(new THREE.Mesh(new THREE.BoxGeometry(0.44, 0.08, 0.33), mat(0x1f74c9)), 0, 0.1, 0));
      const tube = prism(0.32, 0.05, 10, mat(0xcfe6f2, { transparent: true, opacity: 0.8 }));
      g.add(place(tube, 0.02, -0.01, 0));
      g.add(place(prism(0.02, 0.052, 10, mat(0x8a8f94)), 0.19, -0.01, 0));
      g.add(place(prism(0.02, 0.052, 10, mat(0x8a8f94)), -0.15, -0.01, 0));
      const rings = [];
      const thrMat = mat(0x151515);
      // Horizontal thrusters 1-4 (front starboard, front port, rear starboard, rear port) at 45°,
      // vertical 5-8: the layout of ArduSub's "vectored 6DOF" frame (ardusub.com, frame types).
      const horizontal = [[0.2, 0.26, -Math.PI / 4], [0.2, -0.26, Math.PI / 4], [-0.2, 0.26, Math.PI / 4], [-0.2, -0.26, -Math.PI / 4]];
      for (const [x, z, yaw] of horizontal) {
        const t = new THREE.Group();
        t.add(prism(0.09, 0.05, 8, thrMat));
        const ring = new THREE.Mesh(new THREE.TorusGeometry(0.052, 0.012, 4, 10), mat(0x777777));
        ring.rotation.y = Math.PI / 2;
        t.add(ring);
        rings.push(ring);
        t.position.set(x, -0.05, z);
        t.rotation.y = yaw;
        g.add(t);
      }
      const vertical = [[0.12, 0.24], [0.12, -0.24], [-0.12, 0.24], [-0.12, -0.24]];
      for (const [x, z] of vertical) {
        const t = new THREE.Group();
        t.add(new THREE.Mesh(new THREE.CylinderGeometry(0.05, 0.05, 0.09, 8), thrMat));
        const ring = new THREE.Mesh(new THREE.TorusGeometry(0.052, 0.012, 4, 10), mat(0x777777));
        ring.rotation.x = Math.PI / 2;
        t.add(ring);
        rings.push(ring);
        t.position.set(x, 0.08, z);
        g.add(t);
      }
      g.userData.rings = rings;
      return g;
    }

    // The pair's two vehicles (version 1), or a fleet's parts (version 2, below).
    const boat = fleet ? null : makeBoat();
    const rov = fleet ? null : makeRov();
    for (const o of fleet ? [] : [boat, rov]) {
      o.matrixAutoUpdate = false;
      scene.add(o);
    }

    // A fleet's vehicle with no model of its own (not a preset): its hull box in body axes (a
    // default 0.5 × 0.5 × 0.25 m box when the run does not know its hull), yellow, its bow dark so
    // that its heading shows.
    function makeHullBox(hull) {
      const h = (hull && hull.half_extents) || [0.25, 0.25, 0.125];
      const c = (hull && hull.center) || [0, 0, 0];
      const g = new THREE.Group();
      g.add(place(new THREE.Mesh(new THREE.BoxGeometry(2 * h[0], 2 * h[2], 2 * h[1]), mat(0xf2c12e)), c[0], -c[2], c[1]));
      const bow = new THREE.Mesh(new THREE.BoxGeometry(0.2 * h[0], 2.02 * h[2], 2.02 * h[1]), mat(0x202428));
      g.add(place(bow, c[0] + 0.9 * h[0], -c[2], c[1]));
      return g;
    }
    // An anchor is a fixed point: a marker drawn a few pixels wide at least (its scale follows the
    // camera's distance, as the tether's width does).
    const anchorRadius = 0.25;
    const fleetVehicles = [], fleetMasses = [], fleetAnchors = [];
    if (fleet) {
      for (const v of data.vehicles || []) {
        const obj = v.model === 'bluerov2_heavy' ? makeRov() : v.model === 'blueboat' ? makeBoat() : makeHullBox(v.hull);
        obj.matrixAutoUpdate = false;
        scene.add(obj);
        fleetVehicles.push({ data: v, obj, pose: poseOf(v, { i: 0, u: 0 }) });
      }
      const massMat = mat(0xe0702a);
      for (const m of data.point_masses || []) {
        const obj = new THREE.Mesh(new THREE.SphereGeometry(Math.max(m.diameter, 0.05) / 2, 16, 10), massMat);
        scene.add(obj);
        fleetMasses.push({ data: m, obj, at: { n: NaN, e: NaN, d: NaN } });
      }
      const anchorGeom = new THREE.OctahedronGeometry(anchorRadius, 0);
      const anchorMat = mat(0xb03a2e);
      for (const a of data.anchors || []) {
        const obj = new THREE.Mesh(anchorGeom, anchorMat);
        obj.position.copy(toScene(a.position[0], a.position[1], a.position[2]));
        scene.add(obj);
        fleetAnchors.push({ data: a, obj });
      }
    }

    // -- sea surface: a grid around what the camera looks at, heights from makeWaves --
    const seaGeom = new THREE.BufferGeometry();
    const seaN = seaGrid + 1;
    const seaPos = new Float32Array(seaN * seaN * 3);
    const seaZeta = new Float64Array((seaGrid - 1) * (seaGrid - 1));
    seaGeom.setAttribute('position', new THREE.BufferAttribute(seaPos, 3));
    const seaIdx = [];
    for (let i = 0; i < seaGrid; ++i)
      for (let j = 0; j < seaGrid; ++j) {
        const a = i * seaN + j, b = a + 1, c = a + seaN, d = c + 1;
        seaIdx.push(a, b, c, b, d, c);
      }
    seaGeom.setIndex(seaIdx);
    // Unlit, with the light worked out per vertex here: per-pixel lighting of a surface that
    // fills the screen is most of a frame's cost in software WebGL.
    const seaCol = new Float32Array(seaN * seaN * 3);
    seaGeom.setAttribute('color', new THREE.BufferAttribute(seaCol, 3));
    const seaMat = new THREE.MeshBasicMaterial({
      vertexColors: true, transparent: true, opacity: 0.6, side: THREE.DoubleSide, depthWrite: false,
    });
    const seaBase = new THREE.Color(0x1b6f93), seaLit = new THREE.Color(0x8fd0e8);
    const sunDir = new THREE.Vector3(-40, 80, 30).normalize();
    const sea = new THREE.Mesh(seaGeom, seaMat);
    sea.frustumCulled = false;
    sea.renderOrder = 2;
    scene.add(sea);
    function updateSea(centreN, centreE, size, t) {
      const h = size / seaGrid;
      const n0 = Math.round(centreN / h) * h - size / 2; // snapped: the grid does not swim
      const e0 = Math.round(centreE / h) * h - size / 2;
      // The outermost ring of vertices is a flat skirt out to the horizon (the fog hides it).
      const far = 2500;
      const coord = (c0, i) => (i === 0 ? c0 - far : i === seaGrid ? c0 + size + far : c0 + i * h);
      waves.grid(n0 + h, e0 + h, h, seaGrid - 1, t, seaZeta); // the inner vertices
      let k = 0;
      for (let i = 0; i < seaN; ++i) {
        const n = coord(n0, i);
        for (let j = 0; j < seaN; ++j) {
          const e = coord(e0, j);
          const edge = i === 0 || j === 0 || i === seaGrid || j === seaGrid;
          seaPos[k++] = n;
          seaPos[k++] = edge ? 0 : seaZeta[(i - 1) * (seaGrid - 1) + (j - 1)];
          seaPos[k++] = e;
        }
      }
      seaGeom.attributes.position.needsUpdate = true;
      seaGeom.computeVertexNormals();
      // colour: the base, lit by the sun's angle to the surface (Lambert), in linear RGB
      const nrm = seaGeom.attributes.normal.array;
      for (let v = 0; v < seaN * seaN; ++v) {
        const l = Math.max(0, nrm[3 * v] * sunDir.x + nrm[3 * v + 1] * sunDir.y + nrm[3 * v + 2] * sunDir.z);
        const f = Math.pow(l, 8); // the bright faces turned to the sun
        seaCol[3 * v] = seaBase.r * (0.55 + 0.45 * l) + (seaLit.r - seaBase.r) * f;
        seaCol[3 * v + 1] = seaBase.g * (0.55 + 0.45 * l) + (seaLit.g - seaBase.g) * f;
        seaCol[3 * v + 2] = seaBase.b * (0.55 + 0.45 * l) + (seaLit.b - seaBase.b) * f;
      }
      seaGeom.attributes.color.needsUpdate = true;
      seaGeom.computeBoundingSphere();
    }

    // -- seabed and obstacles --
    const seabedDepth = data.seabed && Number.isFinite(data.seabed.depth) ? data.seabed.depth : null;
    if (seabedDepth !== null) {
      const bed = new THREE.Mesh(new THREE.PlaneGeometry(600, 600), mat(0x8c7a5b));
      bed.rotation.x = -Math.PI / 2;
      bed.position.y = -seabedDepth;
      scene.add(bed);
      const grid = new THREE.GridHelper(200, 40, 0x5e513b, 0x6e604a);
      grid.position.y = -seabedDepth + 0.02;
      scene.add(grid);
    } else {
      // No seabed: deep water far below, so that the sea seen through its surface is dark
      // rather than the sky's colour.
      let deepest = 0;
      if (fleet) {
        const tracks = fleetVehicles.map((v) => v.data.d).concat(fleetMasses.map((m) => m.data.d),
          fleetAnchors.map((a) => [a.data.position[2]]));
        for (const track of tracks) for (const d of track) deepest = Math.max(deepest, num(d) || 0);
      } else {
        for (const k of ['rov', 'boat']) for (const d of series[k].d) deepest = Math.max(deepest, num(d) || 0);
      }
      const abyss = new THREE.Mesh(new THREE.PlaneGeometry(6000, 6000), new THREE.MeshBasicMaterial({ color: 0x0b3048 }));
      abyss.rotation.x = -Math.PI / 2;
      abyss.position.y = -(deepest + 25);
      scene.add(abyss);
    }
    const obstacleMat = mat(0x9b6b43);
    for (const ob of data.obstacles || []) {
      if (ob.type === 'cylinder') {
        const a = toScene(...ob.from), b = toScene(...ob.to);
        const len = a.distanceTo(b);
        const m = new THREE.Mesh(new THREE.CylinderGeometry(ob.radius, ob.radius, len, 16), obstacleMat);
        m.position.copy(a).add(b).multiplyScalar(0.5);
        m.quaternion.setFromUnitVectors(new THREE.Vector3(0, 1, 0), b.clone().sub(a).normalize());
        scene.add(m);
      } else if (ob.type === 'box') {
        const [a, b, c] = ob.half_extents;
        const m = new THREE.Mesh(new THREE.BoxGeometry(2 * a, 2 * c, 2 * b), obstacleMat);
        m.position.copy(toScene(...ob.center));
        m.matrixAutoUpdate = false;
        const R = rotationScene(0, 0, ob.yaw || 0);
        m.matrix.set(R[0][0], R[0][1], R[0][2], m.position.x, R[1][0], R[1][1], R[1][2], m.position.y,
          R[2][0], R[2][1], R[2][2], m.position.z, 0, 0, 0, 1);
        scene.add(m);
      } else if (ob.type === 'heightfield') {
        const [rows, cols] = ob.size;
        const g = new THREE.BufferGeometry();
        const p = new Float32Array(rows * cols * 3);
        for (let i = 0; i < rows; ++i)
          for (let j = 0; j < cols; ++j) {
            const k = (i * cols + j) * 3;
            p[k] = ob.origin[0] + i * ob.spacing[0];
            p[k + 1] = -ob.depth[i * cols + j];
            p[k + 2] = ob.origin[1] + j * ob.spacing[1];
          }
        const idx = [];
        for (let i = 0; i + 1 < rows; ++i)
          for (let j = 0; j + 1 < cols; ++j) {
            const a = i * cols + j;
            idx.push(a, a + 1, a + cols, a + 1, a + cols + 1, a + cols);
          }
        g.setAttribute('position', new THREE.BufferAttribute(p, 3));
        g.setIndex(idx);
        g.computeVertexNormals();
        scene.add(new THREE.Mesh(g, mat(0x8c7a5b, { side: THREE.DoubleSide })));
      }
    }

    // -- waypoints (the ROV's; each of a fleet's vehicles its own) and the ROV's target --
    function drawWaypoints(list) {
      const wps = (list || []).map((w) => toScene(w[0], w[1], w[2]));
      if (!wps.length) return;
      const wpMat = new THREE.MeshBasicMaterial({ color: 0xf27ee6 });
      const sphere = new THREE.SphereGeometry(0.08, 8, 6);
      for (const p of wps) scene.add(place(new THREE.Mesh(sphere, wpMat), p.x, p.y, p.z));
      const line = new THREE.Line(new THREE.BufferGeometry().setFromPoints(wps),
        new THREE.LineDashedMaterial({ color: 0xf27ee6, dashSize: 0.4, gapSize: 0.25 }));
      line.computeLineDistances();
      scene.add(line);
    }
    if (fleet) for (const v of fleetVehicles) drawWaypoints(v.data.waypoints);
    else drawWaypoints(data.waypoints);
    const target = new THREE.Mesh(new THREE.OctahedronGeometry(0.22, 0), new THREE.MeshBasicMaterial({ color: 0x4cff7a, wireframe: true }));
    scene.add(target);

    // -- tether: one cylinder per segment (instanced), unlit in its tension colour --
    let maxSegments = 1;
    for (const p of nodes.position) maxSegments = Math.max(maxSegments, p.length / 3 - 1);
    // Drawn thicker than the 7.6 mm cable, to be seen: at least 0.025 m, and wider from afar
    // (tetherWidth scales the radius, set from the camera's distance each frame).
    const tetherRadius = 0.025;
    let tetherWidth = 1;
    function makeLineMesh(segments) {
      const m = new THREE.InstancedMesh(new THREE.CylinderGeometry(tetherRadius, tetherRadius, 1, 6, 1, true),
        new THREE.MeshBasicMaterial({ color: 0xffffff, fog: false }), segments); // its colour is data: no fog
      m.frustumCulled = false;
      m.instanceMatrix.setUsage(THREE.DynamicDrawUsage);
      m.setColorAt(0, new THREE.Color(0xffffff)); // creates instanceColor
      scene.add(m);
      return m;
    }
    const tether = fleet ? null : makeLineMesh(maxSegments);
    const up = new THREE.Vector3(0, 1, 0);
    const tmpA = new THREE.Vector3(), tmpB = new THREE.Vector3(), tmpD = new THREE.Vector3();
    const tmpQ = new THREE.Quaternion(), tmpS = new THREE.Vector3(), tmpM = new THREE.Matrix4(), tmpC = new THREE.Color();
    const segColours = []; // hex of each segment's colour at the current time
    let tetherNow = { position: [], tension: [] };
    // The segments of a line through nodes p (flat n, e, d), segment s in the colour of the
    // tension tensionOf(s) [N].
    function drawLine(mesh, p, tensionOf) {
      const count = Math.max(0, p.length / 3 - 1);
      mesh.count = count;
      for (let s = 0; s < count; ++s) {
        tmpA.set(p[3 * s], -p[3 * s + 2], p[3 * s + 1]);
        tmpB.set(p[3 * s + 3], -p[3 * s + 5], p[3 * s + 4]);
        tmpD.subVectors(tmpB, tmpA);
        const len = tmpD.length();
        if (len > 0) tmpQ.setFromUnitVectors(up, tmpD.divideScalar(len));
        tmpS.set(tetherWidth, Math.max(len, 1e-6), tetherWidth);
        tmpM.compose(tmpA.add(tmpB).multiplyScalar(0.5), tmpQ, tmpS);
        mesh.setMatrixAt(s, tmpM);
        const rgb = tensionColour(tensionOf(s));
        if (mesh === tether) segColours[s] = hex(rgb);
        mesh.setColorAt(s, tmpC.setRGB(rgb[0] / 255, rgb[1] / 255, rgb[2] / 255, THREE.SRGBColorSpace));
      }
      mesh.instanceMatrix.needsUpdate = true;
      if (mesh.instanceColor) mesh.instanceColor.needsUpdate = true;
    }
    function updateTether(t) {
      tetherNow = tetherAt(nodes, t);
      segColours.length = Math.max(0, tetherNow.position.length / 3 - 1);
      drawLine(tether, tetherNow.position, (s) => num(tetherNow.tension[s]));
    }
    // A fleet's lines. Their segments' tensions are not logged (only the force at each end): a
    // segment's colour is the tension interpolated linearly between the two end forces by its
    // index along the line, which is the hanging line's own tension when its weight dominates
    // (the tension of a hanging line changes linearly with depth) and an estimate otherwise.
    const fleetLines = (fleet ? data.tethers || [] : []).map((l) => {
      let most = 1;
      for (const p of (l.nodes && l.nodes.position) || []) most = Math.max(most, p.length / 3 - 1);
      return { data: l, mesh: makeLineMesh(most), now: { position: [], tension: [] }, ends: [NaN, NaN] };
    });
    function updateFleetLines(t, loc) {
      for (const l of fleetLines) {
        l.now = tetherAt(l.data.nodes, t);
        const a = lerpAt(l.data.tension_start, loc), b = lerpAt(l.data.tension_end, loc);
        const count = Math.max(0, l.now.position.length / 3 - 1);
        l.ends = [a, b];
        l.now.tension = Array.from({ length: count }, (_, s) => a + ((b - a) * (s + 0.5)) / count);
        drawLine(l.mesh, l.now.position, (s) => num(l.now.tension[s]));
      }
    }

    // -- legend: drawn from the same colour map --
    const legendCanvas = document.getElementById('legend-bar');
    {
      const ctx = legendCanvas.getContext('2d');
      const h = legendCanvas.height;
      for (let y = 0; y < h; ++y) {
        ctx.fillStyle = hex(colourAt(1 - y / (h - 1)));
        ctx.fillRect(0, y, legendCanvas.width, 1);
      }
      const ticks = document.getElementById('legend-ticks');
      for (let i = 0; i <= 4; ++i) {
        const s = document.createElement('span');
        const v = scaleMax - ((scaleMax - scaleMin) * i) / 4;
        s.textContent = v >= 100 ? v.toFixed(0) : v.toFixed(1);
        s.style.top = `${(i * 100) / 4}%`;
        ticks.appendChild(s);
      }
    }
    function legendPixel(y) {
      const px = legendCanvas.getContext('2d').getImageData(legendCanvas.width >> 1, y, 1, 1).data;
      return hex([px[0], px[1], px[2]]);
    }

    // -- HUD --
    const $ = (id) => document.getElementById(id);
    const thrusterBars = [];
    if (!fleet) {
      const box = $('hud-thrusters');
      const names = ['boat P', 'boat S', 'rov 1', 'rov 2', 'rov 3', 'rov 4', 'rov 5', 'rov 6', 'rov 7', 'rov 8'];
      for (const name of names) {
        const label = document.createElement('div');
        label.className = 'thr-name';
        label.textContent = name;
        const bar = document.createElement('div');
        bar.className = 'thr-bar';
        const fill = document.createElement('div');
        fill.className = 'thr-fill';
        bar.appendChild(fill);
        box.appendChild(label);
        box.appendChild(bar);
        thrusterBars.push(fill);
      }
    }
    const fmt = (v, digits, unit) => (Number.isFinite(v) ? `${v.toFixed(digits)} ${unit}` : '–');
    const labels = {};
    for (const [key, text] of fleet ? [] : [['boat', 'BlueBoat'], ['rov', 'BlueROV2 Heavy']]) {
      const el = document.createElement('div');
      el.className = 'label';
      el.textContent = text;
      $('labels').appendChild(el);
      labels[key] = el;
    }
    // A fleet's HUD: the pair's table and thruster bars give way to a row per vehicle and point
    // mass (depth) and per line (unstretched length, force at each end); a label on every part.
    const fleetCells = { bodies: [], lines: [] };
    const fleetLabels = [];
    if (fleet) {
      // (style, not the hidden attribute, which the stylesheet's display: grid would override)
      $('hud-thrusters').style.display = 'none';
      if ($('hud-thrusters').previousElementSibling) $('hud-thrusters').previousElementSibling.style.display = 'none';
      const table = $('hud-table');
      table.textContent = '';
      const row = (cells, tag) => {
        const tr = document.createElement('tr');
        const out = cells.map((text) => {
          const c = document.createElement(tag);
          c.textContent = text;
          tr.appendChild(c);
          return c;
        });
        table.appendChild(tr);
        return out;
      };
      const bodies = fleetVehicles.concat(fleetMasses);
      if (bodies.length) row(['', 'depth'], 'th');
      for (const b of bodies) fleetCells.bodies.push(row([b.data.name, ''], 'td')[1]);
      if (fleetLines.length) row(['line', 'length', 'start', 'end'], 'th');
      for (const l of fleetLines) fleetCells.lines.push(row([l.data.name, '', '', ''], 'td').slice(1));
      const label = (text, at, lift) => {
        const el = document.createElement('div');
        el.className = 'label';
        el.textContent = text;
        $('labels').appendChild(el);
        fleetLabels.push({ el, at, lift });
      };
      for (const v of fleetVehicles) label(v.data.name, () => v.pose, 0.6);
      for (const m of fleetMasses) label(m.data.name, () => m.at, m.data.diameter / 2 + 0.3);
      for (const a of fleetAnchors) {
        const [n, e, d] = a.data.position;
        label(a.data.name, () => ({ n, e, d }), 0.5);
      }
    }
    // The part the underwater camera follows: ?focus=NAME (a vehicle or point mass), else the
    // first vehicle that starts under water, else the first vehicle or point mass.
    const fleetFocus = (() => {
      if (!fleet) return null;
      const bodies = fleetVehicles.concat(fleetMasses);
      return bodies.find((b) => b.data.name === query.get('focus')) ||
        fleetVehicles.find((v) => num(v.data.d[0]) > 1) || bodies[0] || null;
    })();
    const focusPose = () => {
      if (!fleetFocus) return { n: 0, e: 0, d: 0, yaw: 0 };
      return fleetFocus.pose || Object.assign({ yaw: 0 }, fleetFocus.at);
    };
    // Where a fleet is: the box around its vehicles, point masses and anchors (the follow camera
    // keeps it all in the picture).
    function fleetBox() {
      const lo = new THREE.Vector3(Infinity, Infinity, Infinity), hi = new THREE.Vector3(-Infinity, -Infinity, -Infinity);
      const add = (p) => {
        const v = toScene(p.n, p.e, p.d);
        if (!Number.isFinite(v.x) || !Number.isFinite(v.y) || !Number.isFinite(v.z)) return;
        lo.min(v);
        hi.max(v);
      };
      for (const v of fleetVehicles) add(v.pose);
      for (const m of fleetMasses) add(m.at);
      for (const a of fleetAnchors) add({ n: a.data.position[0], e: a.data.position[1], d: a.data.position[2] });
      if (!(lo.x <= hi.x)) return { centre: new THREE.Vector3(), size: 0 };
      return { centre: lo.clone().add(hi).multiplyScalar(0.5), size: lo.distanceTo(hi) };
    }

    // -- camera --
    const orbit = { target: new THREE.Vector3(), distance: 20, azimuth: -2.3, elevation: 0.45 };
    const followOffset = { azimuth: -2.3, elevation: 0.42, zoom: 1 };
    const underOffset = { azimuth: 0.35, elevation: -0.3, zoom: 1 };
    let boatPose, rovPose;
    function placeCamera() {
      let look, dist, az, el;
      if (cameraMode === 'follow') {
        if (fleet) {
          // the whole fleet in the picture, as the pair's two vehicles: the box's diagonal as
          // their distance
          const box = fleetBox();
          look = box.centre;
          dist = Math.max(6, 1.25 * box.size + 4) * followOffset.zoom;
        } else {
          const b = toScene(boatPose.n, boatPose.e, boatPose.d);
          const r = toScene(rovPose.n, rovPose.e, rovPose.d);
          look = b.clone().add(r).multiplyScalar(0.5);
          // both in the picture: the half-separation within the half-height's 27.5° view
          dist = Math.max(6, 1.25 * b.distanceTo(r) + 4) * followOffset.zoom;
        }
        az = followOffset.azimuth;
        el = followOffset.elevation;
      } else if (cameraMode === 'underwater') {
        const p = fleet ? focusPose() : rovPose; // a fleet: its focus (?focus=)
        const r = toScene(p.n, p.e, p.d);
        look = r.clone().add(new THREE.Vector3(0, 1.2, 0)); // the ROV low in the picture, the line above
        dist = 6 * underOffset.zoom;
        az = Math.PI + p.yaw + underOffset.azimuth; // astern of the ROV
        el = underOffset.elevation;
      } else {
        look = orbit.target;
        dist = orbit.distance;
        az = orbit.azimuth;
        el = orbit.elevation;
      }
      // az: from north towards east (as NED yaw); el: above the horizontal
      camera.position.set(
        look.x + dist * Math.cos(el) * Math.cos(az),
        look.y + dist * Math.sin(el),
        look.z + dist * Math.cos(el) * Math.sin(az));
      if (cameraMode === 'underwater') {
        // keep the camera at least 1.5 m below the surface above it
        const zeta = waves.elevation(camera.position.x, camera.position.z, time);
        camera.position.y = Math.min(camera.position.y, zeta - 1.5);
      }
      camera.lookAt(look);
      camera.updateMatrixWorld();
      return look;
    }

    // -- one frame of state at `time` --
    let frames = 0;
    let hudTime = -Infinity;
    function update() {
      const loc = locate(series.t, time);
      if (fleet) return updateFleet(loc);
      boatPose = pose(series, 'boat', loc);
      rovPose = pose(series, 'rov', loc);
      setPose(boat, boatPose);
      setPose(rov, rovPose);
      const tn = lerpAt(series.rov_target.n, loc), te = lerpAt(series.rov_target.e, loc), td = lerpAt(series.rov_target.d, loc);
      target.visible = Number.isFinite(tn) && Number.isFinite(te) && Number.isFinite(td);
      if (target.visible) target.position.copy(toScene(tn, te, td));
      target.rotation.y = time * 0.8;
      const look = placeCamera();
      tetherWidth = Math.max(1, (0.004 * camera.position.distanceTo(look)) / tetherRadius);
      updateTether(time);
      updateSeaAndSky(look);
      // thruster rings
      const rc = series.rov_command[loc.i] ? lerpRow(series.rov_command, loc) : [];
      rov.userData.rings.forEach((ring, k) => {
        const c = num(rc[k]);
        ring.material.color.setHex(!(Math.abs(c) > 0.02) ? 0x777777 : c > 0 ? 0xf08c3c : 0x4aa3df);
      });
      updateHud(loc, rc);
    }
    // The sea around where the camera looks, and the sky or the deep behind everything.
    function updateSeaAndSky(look) {
      const span = cameraMode === 'underwater' ? 80 : Math.min(Math.max(4 * camera.position.distanceTo(look), 60), 500);
      updateSea(look.x, look.z, span, time);
      const below = camera.position.y < waves.elevation(camera.position.x, camera.position.z, time);
      scene.background.copy(below ? deepColour : skyColour);
      scene.fog.color.copy(below ? deepColour : skyColour);
      scene.fog.near = below ? 2 : 150;
      scene.fog.far = below ? 45 : 900;
    }
    // A fleet at `time` (loc: its place in the log): every vehicle at its pose, every point mass
    // at its position, the camera, the lines, the sea, the HUD.
    function updateFleet(loc) {
      for (const v of fleetVehicles) {
        v.pose = poseOf(v.data, loc);
        setPose(v.obj, v.pose);
      }
      for (const m of fleetMasses) {
        m.at = { n: lerpAt(m.data.n, loc), e: lerpAt(m.data.e, loc), d: lerpAt(m.data.d, loc) };
        m.obj.position.copy(toScene(m.at.n, m.at.e, m.at.d));
      }
      target.visible = false; // a fleet's controllers' targets are not logged
      const look = placeCamera();
      const far = camera.position.distanceTo(look);
      tetherWidth = Math.max(1, (0.004 * far) / tetherRadius);
      const anchorScale = Math.max(1, (0.008 * far) / anchorRadius);
      for (const a of fleetAnchors) a.obj.scale.setScalar(anchorScale);
      updateFleetLines(time, loc);
      updateSeaAndSky(look);
      updateFleetHud(loc);
    }
    function updateFleetHud(loc) {
      const now = performance.now();
      if (playing && now - hudTime < 100) return; // as the pair's (updateHud)
      hudTime = now;
      $('hud-time').textContent = `t = ${time.toFixed(1)} s`;
      $('time-label').textContent = `${time.toFixed(1)} / ${duration.toFixed(1)} s`;
      const tl = $('timeline');
      if (document.activeElement !== tl || playing) tl.value = String(time);
      fleetVehicles.concat(fleetMasses).forEach((b, k) => {
        fleetCells.bodies[k].textContent = fmt((b.pose || b.at).d, 2, 'm');
      });
      let nodeCount = 0;
      fleetLines.forEach((l, k) => {
        const [len, start, end] = fleetCells.lines[k];
        len.textContent = fmt(lerpAt(l.data.length, loc), 1, 'm');
        start.textContent = fmt(l.ends[0], 1, 'N');
        end.textContent = fmt(l.ends[1], 1, 'N');
        nodeCount += l.now.position.length / 3;
      });
      $('hud-tether').textContent = `${fleetLines.length} line${fleetLines.length === 1 ? '' : 's'}, ${nodeCount} nodes; ` +
        'colours: between the end forces';
    }
    function updateHud(loc, rc) {
      // While playing, the text and the timeline change at most every 0.1 s of wall clock
      // (repainting them is a good part of a frame in software rendering).
      const now = performance.now();
      if (playing && now - hudTime < 100) return;
      hudTime = now;
      $('hud-time').textContent = `t = ${time.toFixed(1)} s`;
      $('time-label').textContent = `${time.toFixed(1)} / ${duration.toFixed(1)} s`;
      const tl = $('timeline');
      if (document.activeElement !== tl || playing) tl.value = String(time);
      $('hud-boat-depth').textContent = fmt(boatPose.d, 2, 'm');
      $('hud-rov-depth').textContent = fmt(rovPose.d, 2, 'm');
      $('hud-boat-tension').textContent = fmt(lerpAt(series.tension_boat, loc), 1, 'N');
      $('hud-rov-tension').textContent = fmt(lerpAt(series.tension_rov, loc), 1, 'N');
      $('hud-boat-error').textContent = fmt(lerpAt(series.boat_error, loc), 2, 'm');
      $('hud-rov-error').textContent = fmt(lerpAt(series.rov_error, loc), 2, 'm');
      let peak = 0;
      for (const v of tetherNow.tension) peak = Math.max(peak, num(v) || 0);
      $('hud-tether').textContent = `tether: ${Math.max(0, tetherNow.position.length / 3)} nodes, max ${peak.toFixed(1)} N`;
      const bc = series.boat_command[loc.i] ? lerpRow(series.boat_command, loc) : [];
      const cmds = [num(bc[0]), num(bc[1])].concat(Array.from({ length: 8 }, (_, k) => num(rc[k])));
      cmds.forEach((c, k) => {
        const f = thrusterBars[k];
        const v = Number.isFinite(c) ? Math.max(-1, Math.min(1, c)) : 0;
        f.className = `thr-fill ${v >= 0 ? 'pos' : 'neg'}`;
        f.style.left = `${50 + Math.min(v, 0) * 50}%`;
        f.style.width = `${Math.abs(v) * 50}%`;
        f.parentElement.title = Number.isFinite(c) ? c.toFixed(3) : 'no data';
      });
    }

    const project = (v) => {
      const p = v.clone().project(camera);
      const w = renderer.domElement.clientWidth, h = renderer.domElement.clientHeight;
      return { x: ((p.x + 1) / 2) * w, y: ((1 - p.y) / 2) * h, inFront: p.z < 1 && p.z > -1 };
    };
    function placeLabels() {
      for (const { el, at, lift } of fleetLabels) {
        const p = at();
        const q = project(toScene(p.n, p.e, p.d - lift));
        const shown = q.inFront && Number.isFinite(q.x) && Number.isFinite(q.y);
        el.style.display = shown ? '' : 'none';
        if (shown) el.style.transform = `translate(${q.x.toFixed(1)}px, ${q.y.toFixed(1)}px) translate(-50%, -130%)`;
      }
      if (fleet) return;
      for (const [key, p] of [['boat', boatPose], ['rov', rovPose]]) {
        const q = project(toScene(p.n, p.e, p.d - (key === 'boat' ? 0.7 : 0.45)));
        const el = labels[key];
        el.style.display = q.inFront ? '' : 'none';
        el.style.transform = `translate(${q.x.toFixed(1)}px, ${q.y.toFixed(1)}px) translate(-50%, -130%)`;
      }
    }

    function resize() {
      const w = view.clientWidth || window.innerWidth, h = view.clientHeight || window.innerHeight;
      renderer.setSize(w, h, false);
      camera.aspect = w / h;
      camera.updateProjectionMatrix();
    }
    function render() {
      update();
      renderer.render(scene, camera);
      placeLabels();
      frames++;
    }

    // -- controls --
    const playBtn = $('play');
    const syncControls = () => {
      playBtn.textContent = playing ? 'pause' : 'play';
      $('speed').value = String(speed);
      $('camera').value = cameraMode;
    };
    let dirty = true;
    const api = window.kelpReplay;
    function setTime(t) {
      time = Math.min(Math.max(Number(t), tmin), duration);
      render();
      dirty = false;
    }
    function setPlaying(on) {
      playing = !!on;
      if (playing && time >= duration) time = tmin;
      const ratio = playing ? playRatio : fullRatio;
      if (renderer.getPixelRatio() !== ratio) {
        renderer.setPixelRatio(ratio);
        resize();
      }
      dirty = true;
      syncControls();
    }
    function setCamera(mode) {
      if (!['follow', 'underwater', 'orbit'].includes(mode)) throw new Error(`unknown camera '${mode}'`);
      if (mode === 'orbit' && cameraMode !== 'orbit') { // start from where the camera is
        const look = placeCamera();
        orbit.target.copy(look);
        const d = camera.position.clone().sub(look);
        orbit.distance = d.length();
        orbit.elevation = Math.asin(d.y / orbit.distance);
        orbit.azimuth = Math.atan2(d.z, d.x);
      }
      cameraMode = mode;
      syncControls();
      setTime(time);
    }
    const tl = $('timeline');
    tl.min = String(tmin);
    tl.max = String(duration);
    tl.addEventListener('input', () => setTime(parseFloat(tl.value)));
    playBtn.addEventListener('click', () => setPlaying(!playing));
    $('speed').addEventListener('change', (e) => { speed = parseFloat(e.target.value); });
    $('camera').addEventListener('change', (e) => setCamera(e.target.value));
    window.addEventListener('keydown', (e) => {
      if (e.target && e.target.tagName === 'SELECT') return;
      if (e.key === ' ') { setPlaying(!playing); e.preventDefault(); }
      else if (e.key === 'ArrowRight') setTime(time + 1);
      else if (e.key === 'ArrowLeft') setTime(time - 1);
    });
    // Drag: turn the view (pan the orbit target with shift or the right button); wheel: zoom.
    const canvas = renderer.domElement;
    let drag = null;
    canvas.addEventListener('contextmenu', (e) => e.preventDefault());
    canvas.addEventListener('pointerdown', (e) => {
      drag = { x: e.clientX, y: e.clientY, pan: e.shiftKey || e.button === 2 };
      canvas.setPointerCapture(e.pointerId);
    });
    canvas.addEventListener('pointerup', () => { drag = null; });
    canvas.addEventListener('pointermove', (e) => {
      if (!drag) return;
      const dx = e.clientX - drag.x, dy = e.clientY - drag.y;
      drag.x = e.clientX;
      drag.y = e.clientY;
      const o = cameraMode === 'follow' ? followOffset : cameraMode === 'underwater' ? underOffset : orbit;
      if (drag.pan && cameraMode === 'orbit') {
        const s = orbit.distance / 600;
        const fwd = new THREE.Vector3(-Math.cos(orbit.azimuth), 0, -Math.sin(orbit.azimuth));
        const right = new THREE.Vector3(-fwd.z, 0, fwd.x);
        orbit.target.addScaledVector(right, -dx * s).addScaledVector(fwd, dy * s);
      } else {
        o.azimuth += dx * 0.006;
        o.elevation = Math.max(-1.4, Math.min(1.5, o.elevation + dy * 0.006));
      }
      dirty = true;
    });
    canvas.addEventListener('wheel', (e) => {
      const f = Math.exp(e.deltaY * 0.001);
      if (cameraMode === 'orbit') orbit.distance = Math.max(1, Math.min(1500, orbit.distance * f));
      else (cameraMode === 'follow' ? followOffset : underOffset).zoom = Math.max(0.1, Math.min(20, (cameraMode === 'follow' ? followOffset : underOffset).zoom * f));
      dirty = true;
      e.preventDefault();
    }, { passive: false });
    window.addEventListener('resize', () => { resize(); dirty = true; });

    // -- the loop --
    let last = null;
    let fpsProbe = null;
    function loop(now) {
      requestAnimationFrame(loop);
      const dt = last === null ? 0 : Math.min((now - last) / 1000, 0.25);
      last = now;
      if (playing) {
        time += dt * speed;
        if (time >= duration) {
          time = duration;
          setPlaying(false);
        }
      }
      if (playing || dirty) {
        const c0 = performance.now();
        render();
        dirty = false;
        if (fpsProbe) {
          fpsProbe.frames++;
          fpsProbe.work += performance.now() - c0;
        }
      }
    }

    renderer.setPixelRatio(playing ? playRatio : fullRatio);
    resize();
    syncControls();
    setTime(time);

    // ---------------------------------------------------------------------------------------------
    // window.kelpReplay: the page's interface for tests and scripts.
    //   ready                  true once the scene is built and the first frame drawn
    //   data                   the replay data (window.KELP_REPLAY_DATA)
    //   time, duration, playing, speed, cameraMode, frames (frames drawn so far)   (read only)
    //   setTime(t)             shows time t [s] (clamped to the run) and draws it at once
    //   play(), pause(), setSpeed(x) (0.25 … 16), setCamera('follow'|'underwater'|'orbit')
    //   elevation(x, y, t)     ζ [m, up] at NED north x, east y [m], time t [s]: kelp's formula
    //   toScene([n, e, d])     scene coordinates [x, y, z] = [n, −d, e] of a NED point
    //   camera()               {mode, position (scene), matrixWorldInverse, projectionMatrix (16
    //                          numbers each, column-major as three.js), width, height (CSS px of
    //                          the canvas, whose top-left is the page's)}: a scene point p goes to
    //                          ndc = P V p (homogeneous), pixel x = (ndc.x + 1) w / 2,
    //                          y = (1 − ndc.y) h / 2
    //   projected()            {boat, rov, midNode: {x, y (CSS px), world [n, e, d], scene,
    //                          inFront}; midNode also has index (⌊count / 2⌋ of the nodes shown)}
    //                          A fleet (version 2): {vehicles, point_masses, anchors: {name: the
    //                          same for its origin / centre}, tethers: {name: its midNode or null}}
    //   segmentCount(), segmentTension(i) [N], segmentColour(i) ('#rrggbb', the colour drawn)
    //                          (the pair's tether; a fleet: segmentCount(name), ... of its line)
    //   tensionColour(T)       the colour map at tension T [N]
    //   legendTopColour(), legendBottomColour()  the legend bar's top and bottom pixels
    //   tensionScale           {min, max} [N]
    //   setLayers({boat, rov, tether, sea, target, overlay: bool}) shows or hides those (overlay:
    //                          the HUD, legend, timeline and labels) and redraws; a fleet's layers:
    //                          sea, overlay, vehicles, point_masses, anchors, tethers (all of them)
    //                          and 'vehicle:NAME', 'point_mass:NAME', 'anchor:NAME', 'tether:NAME'
    //   fleet                  true for a fleet's data (version 2)
    //   seaVertex(i, j)        the sea mesh's vertex (i, j), 0 < i, j < seaGrid, as [n, e, ζ]
    //                          (float32; the outermost ring is the flat skirt to the horizon)
    //   measureFps(seconds)    plays for `seconds` of wall-clock time and resolves to {fps,
    //                          frames, seconds, workMs (mean JS update + render call per frame),
    //                          pixelRatio (drawing-buffer pixels per CSS pixel while playing)};
    //                          restores the play state afterwards
    function lineNamed(name) {
      const l = fleetLines.find((x) => x.data.name === name);
      if (!l) throw new Error(`no line '${name}'`);
      return l;
    }
    function fleetLayers() {
      const layers = {
        sea: [sea], target: [target],
        vehicles: fleetVehicles.map((v) => v.obj), point_masses: fleetMasses.map((m) => m.obj),
        anchors: fleetAnchors.map((a) => a.obj), tethers: fleetLines.map((l) => l.mesh),
      };
      for (const v of fleetVehicles) layers[`vehicle:${v.data.name}`] = [v.obj];
      for (const m of fleetMasses) layers[`point_mass:${m.data.name}`] = [m.obj];
      for (const a of fleetAnchors) layers[`anchor:${a.data.name}`] = [a.obj];
      for (const l of fleetLines) layers[`tether:${l.data.name}`] = [l.mesh];
      return layers;
    }
    const members = {
      data,
      get time() { return time; },
      get duration() { return duration; },
      get playing() { return playing; },
      get speed() { return speed; },
      get cameraMode() { return cameraMode; },
      get frames() { return frames; },
      tensionScale: { min: scaleMin, max: scaleMax },
      setTime,
      play() { setPlaying(true); },
      pause() { setPlaying(false); },
      setSpeed(x) {
        if (!(x >= 0.25 && x <= 16)) throw new Error('speed must be in [0.25, 16]');
        speed = x;
        syncControls();
      },
      setCamera,
      elevation: (x, y, t) => waves.elevation(x, y, t),
      toScene: (p) => [p[0], -p[2], p[1]],
      camera() {
        return {
          mode: cameraMode,
          software,
          antialias,
          position: camera.position.toArray(),
          matrixWorldInverse: Array.from(camera.matrixWorldInverse.elements),
          projectionMatrix: Array.from(camera.projectionMatrix.elements),
          width: renderer.domElement.clientWidth,
          height: renderer.domElement.clientHeight,
        };
      },
      projected() {
        const one = (n, e, d) => Object.assign(project(toScene(n, e, d)), { world: [n, e, d], scene: [n, -d, e] });
        const midOf = (p) => {
          const count = p.length / 3;
          const mid = Math.floor(count / 2);
          return count ? Object.assign(one(p[3 * mid], p[3 * mid + 1], p[3 * mid + 2]), { index: mid }) : null;
        };
        const p = tetherNow.position;
        const count = p.length / 3;
        const mid = Math.floor(count / 2);
        // the vehicles where they are drawn: their models' origins (the body frame's origin)
        const drawn = (obj) => {
          const m = obj.matrix.elements; // column-major: the translation is 12, 13, 14
          return one(m[12], m[14], -m[13]);
        };
        if (fleet) { // where each part is drawn (a mesh's own position for the spheres and markers)
          const at = (obj) => one(obj.position.x, obj.position.z, -obj.position.y);
          return {
            vehicles: Object.fromEntries(fleetVehicles.map((v) => [v.data.name, drawn(v.obj)])),
            point_masses: Object.fromEntries(fleetMasses.map((m) => [m.data.name, at(m.obj)])),
            anchors: Object.fromEntries(fleetAnchors.map((a) => [a.data.name, at(a.obj)])),
            tethers: Object.fromEntries(fleetLines.map((l) => [l.data.name, midOf(l.now.position)])),
          };
        }
        return {
          boat: drawn(boat),
          rov: drawn(rov),
          midNode: count ? Object.assign(one(p[3 * mid], p[3 * mid + 1], p[3 * mid + 2]), { index: mid }) : null,
        };
      },
      fleet,
      // (the pair's tether; a fleet's line by its name as a second argument)
      segmentCount: (name) => (fleet ? lineNamed(name).mesh.count : tether.count),
      segmentTension: (i, name) => (fleet ? lineNamed(name).now.tension[i] : tetherNow.tension[i]),
      segmentColour(i, name) {
        (fleet ? lineNamed(name).mesh : tether).getColorAt(i, tmpC);
        return '#' + tmpC.getHexString(THREE.SRGBColorSpace);
      },
      tensionColour: (T) => hex(tensionColour(T)),
      legendTopColour: () => legendPixel(0),
      legendBottomColour: () => legendPixel(legendCanvas.height - 1),
      setLayers(layers) {
        const objects = fleet ? fleetLayers() : { boat: [boat], rov: [rov], tether: [tether], sea: [sea], target: [target] };
        for (const [name, on] of Object.entries(layers)) {
          if (objects[name]) for (const o of objects[name]) o.visible = !!on;
          else if (name === 'overlay')
            for (const id of ['hud', 'legend', 'controls', 'labels']) $(id).style.visibility = on ? '' : 'hidden';
          else throw new Error(`unknown layer '${name}'`);
        }
        setTime(time);
      },
      seaVertex(i, j) {
        const k = 3 * (i * seaN + j);
        return [seaPos[k], seaPos[k + 2], seaPos[k + 1]];
      },
      seaGrid,
      measureFps(seconds) {
        const wasPlaying = playing;
        fpsProbe = { frames: 0, work: 0 };
        setPlaying(true);
        const start = performance.now();
        return new Promise((resolve) => {
          setTimeout(() => {
            const elapsed = (performance.now() - start) / 1000;
            const p = fpsProbe;
            fpsProbe = null;
            setPlaying(wasPlaying);
            resolve({ fps: p.frames / elapsed, frames: p.frames, seconds: elapsed, workMs: p.frames ? p.work / p.frames : NaN, pixelRatio: playRatio });
          }, seconds * 1000);
        });
      },
    };
    // defineProperties, not Object.assign, which would copy the getters' values once
    Object.defineProperties(api, Object.getOwnPropertyDescriptors(members));
    api.ready = true;
    requestAnimationFrame(loop);
  }

  window.kelpReplay = { ready: false };
  function start() {
    try {
      init();
    } catch (e) {
      showMessage(`The replay failed to start: ${e.message}`);
      throw e;
    }
  }
  if (document.readyState === 'loading') document.addEventListener('DOMContentLoaded', start);
  else start();
})();
