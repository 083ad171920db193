// The 3D view: base, legs, platform at the estimate, the ground truth as a
// ghost, the position limits as planes and the velocity as an arrow. Every
// position comes from the frame ({B}, z up): the page does no kinematics
// beyond placing the platform's rigid body at its pose.
'use strict';

const LEG_OK = new THREE.Color(0x4caf50);
const LEG_WARN = new THREE.Color(0xff5722);
const AXIS_VECTORS = [new THREE.Vector3(1, 0, 0), new THREE.Vector3(0, 1, 0), new THREE.Vector3(0, 0, 1)];

class PlatformScene {
  constructor(container) {
    this.renderer = new THREE.WebGLRenderer({ antialias: true, preserveDrawingBuffer: true });
    this.renderer.setPixelRatio(window.devicePixelRatio);
    container.appendChild(this.renderer.domElement);
    this.container = container;
    this.scene = new THREE.Scene();
    this.scene.background = new THREE.Color(0x16181d);
    this.camera = new THREE.PerspectiveCamera(45, 1, 0.01, 20);
    this.camera.up.set(0, 0, 1);  // {B}: z up
    this.camera.position.set(0.75, -0.85, 0.7);
    this.controls = new THREE.OrbitControls(this.camera, this.renderer.domElement);
    this.controls.target.set(0, 0, 0.22);
    this.controls.update();
    this.scene.add(new THREE.AmbientLight(0xffffff, 0.55));
    const sun = new THREE.DirectionalLight(0xffffff, 0.7);
    sun.position.set(1, -1, 2);
    this.scene.add(sun);
    const grid = new THREE.GridHelper(1.0, 20, 0x444a55, 0x2a2e36);
    grid.rotation.x = Math.PI / 2;  // the grid in the x-y plane
    this.scene.add(grid);
    this.scene.add(new THREE.AxesHelper(0.15));
    this.legs = [];
    this.arrow = new THREE.ArrowHelper(new THREE.Vector3(1, 0, 0), new THREE.Vector3(), 0.01, 0x03a9f4);
    this.scene.add(this.arrow);
    window.addEventListener('resize', () => this.resize());
    this.resize();
  }

  resize() {
    const w = this.container.clientWidth || 800, h = this.container.clientHeight || 600;
    this.renderer.setSize(w, h);
    this.camera.aspect = w / h;
    this.camera.updateProjectionMatrix();
  }

  // The static parts, from the hello message.
  build(hello) {
    if (this.hello) return;  // a reconnect: the same platform
    const p = hello.platform;
    this.hello = hello;
    const baseRadius = Math.max(...p.base_joints_in_B_m.map((b) => Math.hypot(b[0], b[1])));
    const base = new THREE.Mesh(new THREE.CylinderGeometry(baseRadius * 1.1, baseRadius * 1.1, 0.01, 48),
                                new THREE.MeshStandardMaterial({ color: 0x56607a }));
    base.rotation.x = Math.PI / 2;
    base.position.z = -0.005;
    this.scene.add(base);
    this.platform = this.makePlatform(p.platform_joints_in_P_m, 0xb0bec5, 1.0);
    this.ghost = this.makePlatform(p.platform_joints_in_P_m, 0xffffff, 0.25);
    this.ghost.visible = false;
    for (let i = 0; i < 6; i++) {
      const leg = new THREE.Mesh(new THREE.CylinderGeometry(0.006, 0.006, 1, 12),
                                 new THREE.MeshStandardMaterial({ color: LEG_OK }));
      this.scene.add(leg);
      this.legs.push(leg);
    }
    this.buildLimits(hello.limits.position, p.home_pose);
    this.velocityLimits = hello.limits.velocity;
  }

  makePlatform(joints, colour, opacity) {
    const group = new THREE.Group();
    const shape = new THREE.Shape(joints.map((j) => new THREE.Vector2(j[0], j[1])));
    const material = new THREE.MeshStandardMaterial({
      color: colour, transparent: opacity < 1, opacity, depthWrite: opacity >= 1, side: THREE.DoubleSide });
    group.add(new THREE.Mesh(new THREE.ShapeGeometry(shape), material));
    for (const j of joints) {
      const ball = new THREE.Mesh(new THREE.SphereGeometry(0.008, 12, 8), material);
      ball.position.set(j[0], j[1], j[2]);
      group.add(ball);
    }
    this.scene.add(group);
    return group;
  }

  // Each bound of x, y or z as a translucent plane through the home pose.
  buildLimits(limits, home) {
    for (const l of limits) {
      if (l.axis > 2) continue;
      for (const bound of [l.lower, l.upper]) {
        if (bound === null) continue;
        const plane = new THREE.Mesh(new THREE.PlaneGeometry(0.35, 0.35),
          new THREE.MeshBasicMaterial({ color: 0xff9800, transparent: true, opacity: 0.12,
                                        side: THREE.DoubleSide, depthWrite: false }));
        const centre = new THREE.Vector3(home[0], home[1], home[2]);
        centre.setComponent(l.axis, bound);
        plane.position.copy(centre);
        plane.lookAt(centre.clone().add(AXIS_VECTORS[l.axis]));
        this.scene.add(plane);
      }
    }
  }

  static placeBody(body, q) {
    body.position.set(q[0], q[1], q[2]);
    body.rotation.set(q[3], q[4], q[5], 'ZYX');  // Z-Y-X Euler angles of {P} in {B}
  }

  update(frame) {
    if (!this.hello || !frame.estimate) return;
    const q = frame.estimate.q;
    PlatformScene.placeBody(this.platform, q);
    this.ghost.visible = !!frame.truth;
    if (frame.truth) PlatformScene.placeBody(this.ghost, frame.truth.q);
    const base = this.hello.platform.base_joints_in_B_m;
    if (frame.legs) {
      for (let i = 0; i < 6; i++) {
        const a = new THREE.Vector3(...base[i]);
        const b = new THREE.Vector3(...frame.legs.platform_joints_in_B_m[i]);
        const leg = this.legs[i];
        leg.position.copy(a).add(b).multiplyScalar(0.5);
        leg.scale.set(1, a.distanceTo(b), 1);
        leg.quaternion.setFromUnitVectors(new THREE.Vector3(0, 1, 0), b.clone().sub(a).normalize());
        const use = frame.legs.stroke_use[i];
        // Green in mid-stroke, turning to the warning colour towards either end.
        const nearness = Math.min(1, Math.abs(use - 0.5) * 2);
        leg.material.color.copy(LEG_OK).lerp(LEG_WARN, frame.legs.near_end[i] ? 1 : nearness * 0.5);
      }
    }
    // The velocity as an arrow; red once an axis uses 90 % of its limit.
    const v = new THREE.Vector3(frame.estimate.qd[0], frame.estimate.qd[1], frame.estimate.qd[2]);
    let worst = 0;
    for (const l of this.velocityLimits) {
      const qd = frame.estimate.qd[l.axis];
      if (l.upper !== null && l.upper > 0) worst = Math.max(worst, qd / l.upper);
      if (l.lower !== null && l.lower < 0) worst = Math.max(worst, qd / l.lower);
    }
    const speed = v.length();
    this.arrow.position.set(q[0], q[1], q[2] + 0.03);
    this.arrow.visible = speed > 1e-5;
    if (speed > 1e-5) {
      this.arrow.setDirection(v.clone().normalize());
      this.arrow.setLength(Math.min(0.25, 6 * speed), 0.02, 0.012);  // 6 s of motion, at most 25 cm
      this.arrow.setColor(new THREE.Color(worst > 0.9 ? 0xf44336 : 0x03a9f4));
    }
  }

  render() {
    this.controls.update();
    this.renderer.render(this.scene, this.camera);
  }
}
