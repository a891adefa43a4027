#include "report/animation_page.hpp"

#include "report/svg_plot.hpp"

#include <nlohmann/json.hpp>

#include <cmath>
#include <stdexcept>

namespace hamel {

namespace {

#ifdef HAMEL_HAVE_THREE_JS
// The text of three.min.js and OrbitControls.js, cut into literals by generator/embed_file.cmake.
const char* const three_js[] = {
#include "report/three_js.inc"
};
const char* const orbit_controls_js[] = {
#include "report/orbit_controls_js.inc"
};

template <std::size_t N>
std::string joined(const char* const (&parts)[N]) {
  std::string s;
  for (const char* p : parts) s += p;
  return s;
}
#endif

// The page's own code: builds the scene from `data` (render_animation_page's JSON), plays it, answers the probe.
// Drawing is three.js's; this only places meshes and reads the controls.
const char* const page_script = R"js(
(function () {
  'use strict';
  var data = JSON.parse(document.getElementById('hamel-data').textContent);
  var up = new THREE.Vector3().fromArray(data.up).normalize();
  var n = data.times.length, t0 = data.times[0], t1 = data.times[n - 1];
  var scene = new THREE.Scene();
  scene.background = new THREE.Color(0xf5f5f2);

  // The extent of the motion, for the camera, the grid and the axes.
  var box = new THREE.Box3();
  data.poses.forEach(function (frame) {
    frame.forEach(function (p, i) {
      var e = data.bodies[i].edges, r = 0.5 * Math.max(e[0], e[1], e[2]);
      box.expandByPoint(new THREE.Vector3(p[0] - r, p[1] - r, p[2] - r));
      box.expandByPoint(new THREE.Vector3(p[0] + r, p[1] + r, p[2] + r));
    });
  });
  data.base.forEach(function (p) { box.expandByPoint(new THREE.Vector3(p[0], p[1], p[2])); });
  if (box.isEmpty()) box.expandByPoint(new THREE.Vector3());
  var centre = box.getCenter(new THREE.Vector3());
  var radius = Math.max(box.getSize(new THREE.Vector3()).length() / 2, 1e-3);

  scene.add(new THREE.HemisphereLight(0xffffff, 0x666655, 0.9));
  var sun = new THREE.DirectionalLight(0xffffff, 0.6);
  sun.position.copy(up).multiplyScalar(3 * radius).add(new THREE.Vector3(radius, radius, radius));
  scene.add(sun);
  var grid = new THREE.GridHelper(4 * radius, 20, 0xaaaaaa, 0xdddddd);
  grid.quaternion.setFromUnitVectors(new THREE.Vector3(0, 1, 0), up);
  grid.position.copy(centre).sub(up.clone().multiplyScalar(up.dot(centre) - up.dot(box.min)));
  scene.add(grid);
  scene.add(new THREE.AxesHelper(0.3 * radius));

  var palette = [0x4477aa, 0xee6677, 0x228833, 0xccbb44, 0x66ccee, 0xaa3377, 0xbbbbbb, 0x997700];
  var meshes = data.bodies.map(function (b, i) {
    var geometry = new THREE.BoxBufferGeometry(b.edges[0], b.edges[1], b.edges[2]);
    var mesh = new THREE.Mesh(geometry, new THREE.MeshStandardMaterial(
        {color: palette[i % palette.length], roughness: 0.7, metalness: 0.05, transparent: true, opacity: 0.8}));
    mesh.name = b.name;
    mesh.add(new THREE.LineSegments(new THREE.EdgesGeometry(geometry), new THREE.LineBasicMaterial({color: 0x333333})));
    scene.add(mesh);
    return mesh;
  });
  var frameAxes = null;
  if (data.base.length) {
    // The frame and its path are drawn over the bodies (a phase's translation is small beside them).
    frameAxes = new THREE.AxesHelper(0.25 * radius);
    frameAxes.name = data.base_name;
    frameAxes.material.depthTest = false;
    frameAxes.material.transparent = true;  // drawn with the bodies, after them (renderOrder)
    frameAxes.renderOrder = 2;
    scene.add(frameAxes);
    var points = new Float32Array(3 * data.base.length);
    data.base.forEach(function (p, k) { points[3 * k] = p[0]; points[3 * k + 1] = p[1]; points[3 * k + 2] = p[2]; });
    var path = new THREE.BufferGeometry();
    path.setAttribute('position', new THREE.BufferAttribute(points, 3));
    var line = new THREE.Line(path, new THREE.LineBasicMaterial({color: 0xcc3311, depthTest: false, transparent: true}));
    line.renderOrder = 1;
    scene.add(line);
  }

  var camera = new THREE.PerspectiveCamera(40, window.innerWidth / window.innerHeight, radius / 100, radius * 100);
  camera.up.copy(up);
  var side = Math.abs(up.x) < 0.9 ? new THREE.Vector3(1, 0, 0) : new THREE.Vector3(0, 1, 0);
  var across = new THREE.Vector3().crossVectors(up, side).normalize();
  side.crossVectors(across, up).normalize();
  camera.position.copy(centre).add(side.multiplyScalar(2.2 * radius)).add(across.multiplyScalar(-1.6 * radius))
      .add(up.clone().multiplyScalar(1.2 * radius));
  camera.lookAt(centre);

  var renderer = null;
  try {
    renderer = new THREE.WebGLRenderer({antialias: true, preserveDrawingBuffer: true});
    renderer.setPixelRatio(window.devicePixelRatio || 1);
    renderer.setSize(window.innerWidth, window.innerHeight);
    document.getElementById('view').appendChild(renderer.domElement);
  } catch (e) {
    renderer = null;
    document.getElementById('notes').textContent += ' WebGL is not available here: nothing is drawn.';
  }
  var controls = null;
  if (renderer && THREE.OrbitControls) {
    controls = new THREE.OrbitControls(camera, renderer.domElement);
    controls.target.copy(centre);
    controls.update();
  }

  var slider = document.getElementById('time'), clock = document.getElementById('clock');
  var button = document.getElementById('play');
  slider.min = t0;
  slider.max = t1;
  slider.step = 'any';
  var now = t0, playing = true, p = new THREE.Vector3(), q = new THREE.Quaternion();
  function place(object, a, b, s) {
    object.position.set(a[0] + s * (b[0] - a[0]), a[1] + s * (b[1] - a[1]), a[2] + s * (b[2] - a[2]));
    object.quaternion.set(a[3], a[4], a[5], a[6]).slerp(q.set(b[3], b[4], b[5], b[6]), s);
  }
  // The poses at time t: linear in position and spherical in rotation between the two samples around t.
  function setTime(t) {
    now = Math.min(Math.max(t, t0), t1);
    var lo = 0, hi = n - 1;
    while (hi - lo > 1) {
      var mid = (lo + hi) >> 1;
      if (data.times[mid] <= now) lo = mid; else hi = mid;
    }
    var s = hi > lo && data.times[hi] > data.times[lo] ? (now - data.times[lo]) / (data.times[hi] - data.times[lo]) : 0;
    if (s >= 1) { lo = hi; s = 0; }
    meshes.forEach(function (mesh, i) { place(mesh, data.poses[lo][i], data.poses[hi][i], s); });
    if (frameAxes) place(frameAxes, data.base[lo], data.base[hi], s);
    slider.value = now;
    clock.textContent = 't = ' + now.toFixed(3) + ' s';
    if (renderer) renderer.render(scene, camera);
  }
  function setPlaying(on) {
    playing = on;
    button.textContent = on ? 'pause' : 'play';
  }
  button.addEventListener('click', function () { setPlaying(!playing); });
  slider.addEventListener('input', function () { setPlaying(false); setTime(parseFloat(slider.value)); });
  if (controls) controls.addEventListener('change', function () { renderer.render(scene, camera); });
  window.addEventListener('resize', function () {
    camera.aspect = window.innerWidth / window.innerHeight;
    camera.updateProjectionMatrix();
    if (renderer) renderer.setSize(window.innerWidth, window.innerHeight);
    setTime(now);
  });

  // The probe: #t=<time> stops there and lists where the scene graph holds every mesh.
  var asked = /(?:^#|&)t=([-+0-9.eE]+)/.exec(window.location.hash);
  if (asked) {
    setPlaying(false);
    setTime(parseFloat(asked[1]));
    scene.updateMatrixWorld(true);
    var positions = {}, orientations = {};
    meshes.concat(frameAxes ? [frameAxes] : []).forEach(function (object) {
      var v = object.getWorldPosition(new THREE.Vector3()), r = object.getWorldQuaternion(new THREE.Quaternion());
      positions[object.name] = [v.x, v.y, v.z];
      orientations[object.name] = [r.x, r.y, r.z, r.w];
    });
    document.getElementById('probe').textContent =
        JSON.stringify({t: now, positions: positions, orientations: orientations});
  } else {
    setTime(t0);
  }
  var last = null;
  function tick(stamp) {
    if (playing && last !== null) {
      var t = now + (stamp - last) / 1000;
      setTime(t > t1 ? t0 : t);
    }
    last = stamp;
    window.requestAnimationFrame(tick);
  }
  window.requestAnimationFrame(tick);
})();
)js";

const char* const page_style = R"css(
html, body { margin: 0; height: 100%; overflow: hidden; font: 14px sans-serif; background: #f5f5f2; }
#view { position: absolute; inset: 0; }
#head { position: absolute; top: 8px; left: 12px; right: 12px; pointer-events: none; }
#head h1 { font-size: 16px; margin: 0 0 4px 0; }
#notes { color: #555; max-width: 60em; }
#bar { position: absolute; bottom: 0; left: 0; right: 0; display: flex; gap: 10px; align-items: center;
       padding: 8px 12px; background: rgba(255, 255, 255, 0.85); }
#time { flex: 1; }
#clock { font-variant-numeric: tabular-nums; min-width: 8em; }
#probe, #errors { display: none; }
)css";

}  // namespace

std::array<double, 4> quaternion_of(const std::array<double, 9>& R) {
  // Shepperd's method: the largest of w², x², y², z² first, so no division by a small number.
  const double tr = R[0] + R[4] + R[8];
  std::array<double, 4> q{};
  if (tr >= R[0] && tr >= R[4] && tr >= R[8]) {
    const double s = 2 * std::sqrt(1 + tr);
    q = {(R[7] - R[5]) / s, (R[2] - R[6]) / s, (R[3] - R[1]) / s, s / 4};
  } else if (R[0] >= R[4] && R[0] >= R[8]) {
    const double s = 2 * std::sqrt(1 + R[0] - R[4] - R[8]);
    q = {s / 4, (R[1] + R[3]) / s, (R[2] + R[6]) / s, (R[7] - R[5]) / s};
  } else if (R[4] >= R[8]) {
    const double s = 2 * std::sqrt(1 + R[4] - R[0] - R[8]);
    q = {(R[1] + R[3]) / s, s / 4, (R[5] + R[7]) / s, (R[2] - R[6]) / s};
  } else {
    const double s = 2 * std::sqrt(1 + R[8] - R[0] - R[4]);
    q = {(R[2] + R[6]) / s, (R[5] + R[7]) / s, s / 4, (R[3] - R[1]) / s};
  }
  const double norm = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
  for (double& c : q) c /= norm;
  return q;
}

const char* missing_three_js() {
  return "this hamel was built without three.js, which `hamel animate` inlines into its pages: install Debian's "
         "libjs-three (/usr/share/javascript/three/three.min.js; tools/install-deps.sh), configure and build again";
}

bool animation_pages_available() {
#ifdef HAMEL_HAVE_THREE_JS
  return true;
#else
  return false;
#endif
}

std::string render_animation_page(const Animation& animation) {
#ifndef HAMEL_HAVE_THREE_JS
  (void)animation;
  throw std::runtime_error(missing_three_js());
#else
  nlohmann::json data;
  data["up"] = animation.up;
  data["times"] = animation.times;
  data["bodies"] = nlohmann::json::array();
  for (const AnimationBody& b : animation.bodies) data["bodies"].push_back({{"name", b.name}, {"edges", b.edges}});
  data["poses"] = animation.poses;
  data["base"] = animation.base;
  data["base_name"] = animation.base_name;
  // Inside <script type="application/json">: only "</" could end the element early.
  std::string json = data.dump();
  for (std::size_t at = json.find("</"); at != std::string::npos; at = json.find("</", at)) json.replace(at, 2, "<\\/");
  std::string notes;
  for (const std::string& note : animation.notes) notes += (notes.empty() ? "" : " ") + xml_escaped(note);
  std::string page;
  page += "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n<title>" +
          xml_escaped(animation.title) + "</title>\n<style>" + page_style + "</style>\n</head>\n<body>\n";
  page += "<div id=\"view\"></div>\n<div id=\"head\"><h1>" + xml_escaped(animation.title) + "</h1><div id=\"notes\">" +
          notes + "</div></div>\n";
  page +=
      "<div id=\"bar\"><button id=\"play\">pause</button><input id=\"time\" type=\"range\" value=\"0\">"
      "<span id=\"clock\"></span></div>\n<pre id=\"probe\"></pre>\n<pre id=\"errors\"></pre>\n";
  page +=
      "<script>window.addEventListener('error', function (e) { var p = document.getElementById('errors'); "
      "p.textContent += (e.message || 'error') + ' (' + (e.filename || '') + ':' + (e.lineno || 0) + ')\\n'; });"
      "</script>\n";
  page += "<script type=\"application/json\" id=\"hamel-data\">" + json + "</script>\n";
  page += "<script>\n" + joined(three_js) + "\n</script>\n";
  page += "<script>\n" + joined(orbit_controls_js) + "\n</script>\n";
  page += "<script>" + std::string(page_script) + "</script>\n</body>\n</html>\n";
  return page;
#endif
}

}  // namespace hamel
