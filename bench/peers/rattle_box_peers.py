#!/usr/bin/env python3
"""Peer-engine benchmark: thesis rattle box case C in MuJoCo (and Drake where it imports).

Prints one JSON object per engine/setting on stdout; progress and notes go to stderr.
See bench/peers/README.md for what is measured, how, and the caveats.

Geometry and drive (SI units, frame of SPEC section 1: x transverse, y vertical, z long axis):
  cube      1 in (25.4 mm) side, 7075 aluminium 2810 kg/m^3 -> 46.05 g, sharp edges (no 0.02 in
            roundover: MuJoCo has no cheap rounded box, Drake's hydroelastic box is sharp too)
  tube      square tube, inner side 1.25 in (31.75 mm), 5 mm walls, 200 mm inner length with end caps
  gravity   -9.81 m/s^2 along y
  drive     transverse x, a(t) = A sin(w t), A = 15 g, w = 2 pi 20 Hz, for t >= settle (no input before)
  friction  mu = 0.17 (single Coulomb coefficient)
"""
import argparse
import json
import math
import os
import sys
import time

import numpy as np

G0 = 9.80665
CUBE_SIDE = 0.0254
TUBE_INNER = 1.25 * 0.0254
WALL_T = 0.005
TUBE_LEN = 0.200
RHO = 2810.0
MU = 0.17
PEAK_G = 15.0
FREQ_HZ = 20.0
GRAVITY = 9.81


def log(*a):
    print(*a, file=sys.stderr, flush=True)


def _idle_ticks():
    idle = {}
    with open("/proc/stat") as f:
        for line in f:
            if line.startswith("cpu") and line[3].isdigit():
                parts = line.split()
                idle[int(parts[0][3:])] = int(parts[4]) + int(parts[5])
    return idle


def pin_one_core():
    """Pin this process to one core: the allowed core that was idlest over a 0.5 s sample."""
    try:
        cpus = sorted(os.sched_getaffinity(0))
        try:
            a = _idle_ticks()
            time.sleep(0.5)
            b = _idle_ticks()
            core = max(cpus, key=lambda c: b.get(c, 0) - a.get(c, 0))
        except (OSError, ValueError, IndexError):
            core = cpus[-1]
        os.sched_setaffinity(0, {core})
        return core
    except (AttributeError, OSError):
        return None


def slip_speed(v, w, r, n):
    """|tangential part of v + w x r| with respect to unit normal n (plain floats: np.cross is slow
    for 3-vectors)."""
    vx = v[0] + w[1] * r[2] - w[2] * r[1]
    vy = v[1] + w[2] * r[0] - w[0] * r[2]
    vz = v[2] + w[0] * r[1] - w[1] * r[0]
    vn = vx * n[0] + vy * n[1] + vz * n[2]
    tx, ty, tz = vx - vn * n[0], vy - vn * n[1], vz - vn * n[2]
    return math.sqrt(tx * tx + ty * ty + tz * tz)


def drive(t, settle):
    """Tube displacement, velocity, acceleration along x. Zero before settle (tube at rest).

    From settle on, x(t) = -(A/w^2) sin(w tau), tau = t - settle, as in the brief; note this implies
    a velocity step of -A/w (-1.17 m/s) at tau = 0 for a tube that was at rest."""
    if t < settle:
        return 0.0, 0.0, 0.0
    A = PEAK_G * G0
    w = 2.0 * math.pi * FREQ_HZ
    tau = t - settle
    return -(A / w**2) * math.sin(w * tau), -(A / w) * math.cos(w * tau), A * math.sin(w * tau)


# ----------------------------------------------------------------------------------------------
# MuJoCo
# ----------------------------------------------------------------------------------------------
def mjcf(step, drive_mode, timeconst, dampratio):
    h = TUBE_INNER / 2
    c = CUBE_SIDE / 2
    t2 = WALL_T / 2
    lz = TUBE_LEN / 2
    outer = h + WALL_T
    walls = [
        ("floor", (0, -(h + t2), 0), (outer, t2, lz + WALL_T)),
        ("ceiling", (0, h + t2, 0), (outer, t2, lz + WALL_T)),
        ("wall_px", (h + t2, 0, 0), (t2, outer, lz + WALL_T)),
        ("wall_nx", (-(h + t2), 0, 0), (t2, outer, lz + WALL_T)),
        ("cap_pz", (0, 0, lz + t2), (outer, outer, t2)),
        ("cap_nz", (0, 0, -(lz + t2)), (outer, outer, t2)),
    ]
    geoms = "\n".join(
        f'      <geom name="{n}" type="box" pos="{p[0]:.9g} {p[1]:.9g} {p[2]:.9g}" '
        f'size="{s[0]:.9g} {s[1]:.9g} {s[2]:.9g}"/>' for n, p, s in walls)
    tube_attr = 'mocap="true"' if drive_mode == "mocap" else ""
    # cube starts centred in x and z, 1 mm above the floor, at rest; it lands during the settle.
    y0 = -h + c + 0.001
    return f"""<mujoco model="rattle_box_case_C">
  <compiler angle="radian"/>
  <option timestep="{step:.9g}" gravity="0 {-GRAVITY} 0" integrator="Euler" cone="elliptic"
          solver="Newton" iterations="50" tolerance="1e-10"/>
  <default>
    <geom condim="3" friction="{MU} 0 0" solref="{timeconst:.9g} {dampratio:.9g}"
          solimp="0.9 0.95 0.001 0.5 2" margin="0"/>
  </default>
  <worldbody>
    <body name="tube" {tube_attr}>
{geoms}
    </body>
    <body name="cube" pos="0 {y0:.9g} 0">
      <freejoint name="cube_free"/>
      <geom name="cube" type="box" size="{c:.9g} {c:.9g} {c:.9g}" density="{RHO}"/>
    </body>
  </worldbody>
</mujoco>
"""


def run_mujoco(step, settle, window, drive_mode, timeconst, dampratio, repeats):
    import mujoco

    xml = mjcf(step, drive_mode, timeconst, dampratio)
    model = mujoco.MjModel.from_xml_string(xml)
    data = mujoco.MjData(model)
    cube = model.body("cube").id
    mass = float(model.body_mass[cube])
    n_settle = int(round(settle / step))
    n_win = int(round(window / step))
    n_total = n_settle + n_win

    # open-loop input sequence, one row per step, evaluated at the step's start time
    times = np.arange(n_total) * step
    if drive_mode == "mocap":
        spec = mujoco.mjtState.mjSTATE_MOCAP_POS
        ctrl = np.zeros((n_total, 3))
        ctrl[:, 0] = [drive(t, settle)[0] for t in times]
    else:
        # accelerating-frame drive: tube fixed, cube gets the inertial force -m a(t) along x
        spec = mujoco.mjtState.mjSTATE_QFRC_APPLIED
        ctrl = np.zeros((n_total, model.nv))
        ctrl[:, 0] = [-mass * drive(t, settle)[2] for t in times]

    # ---- timing pass: pure C stepping loop (mujoco.rollout, one thread, same inputs) ----
    from mujoco import rollout

    fullspec = mujoco.mjtState.mjSTATE_FULLPHYSICS
    mujoco.mj_resetData(model, data)
    s0 = np.zeros(mujoco.mj_stateSize(model, fullspec))
    mujoco.mj_getState(model, data, s0, fullspec)
    walls = []
    state_out = None
    cpus = []
    for _ in range(repeats):
        c0 = time.process_time()
        t0 = time.perf_counter()
        state_out, _ = rollout.rollout(model, data, s0[None, :], ctrl[None, :, :], control_spec=spec,
                                       initial_warmstart=np.zeros((1, model.nv)))
        walls.append(time.perf_counter() - t0)
        cpus.append(time.process_time() - c0)
    wall = min(walls)
    cpu = min(cpus)
    final_rollout = state_out[0, -1].copy()

    # ---- metrics pass: Python loop over mj_step, same inputs, same trajectory ----
    mujoco.mj_resetData(model, data)
    dqpos = model.jnt_qposadr[model.body_jntadr[cube]]
    f6 = np.zeros(6)
    sum_n = 0.0
    sum_p = 0.0
    max_pen = 0.0
    max_contacts = 0
    loop_t0 = time.perf_counter()
    for k in range(n_total):
        if drive_mode == "mocap":
            data.mocap_pos[0, 0] = ctrl[k, 0]
        else:
            data.qfrc_applied[0] = ctrl[k, 0]
        mujoco.mj_step(model, data)
        if k < n_settle:
            continue
        # after mj_step: data.contact / efc_force / xpos / xmat belong to the step's start
        # configuration, data.qvel is the end-of-step velocity v_{n+1} (what the step's impulses act on)
        wall_v = drive(times[k], settle)[1] if drive_mode == "mocap" else 0.0
        v_lin = data.qvel[0:3].tolist()
        omega_w = (data.xmat[cube].reshape(3, 3) @ data.qvel[3:6]).tolist()
        com = data.xpos[cube].tolist()
        ncon = data.ncon
        max_contacts = max(max_contacts, ncon)
        for i in range(ncon):
            con = data.contact[i]
            mujoco.mj_contactForce(model, data, i, f6)
            fn = f6[0]
            if fn <= 0.0:
                continue
            n = con.frame[0:3].tolist()
            # cube is geom2 or geom1; the normal points from geom1 to geom2; |v_slip| is sign-free
            p = con.pos
            rel_v = (v_lin[0] - wall_v, v_lin[1], v_lin[2])
            sum_n += fn
            sum_p += fn * slip_speed(rel_v, omega_w, (p[0] - com[0], p[1] - com[1], p[2] - com[2]), n)
            max_pen = max(max_pen, -con.dist)
    loop_wall = time.perf_counter() - loop_t0
    final_loop = np.zeros_like(s0)
    mujoco.mj_getState(model, data, final_loop, fullspec)
    # rollout output omits nothing we compare: time, qpos, qvel
    dev = float(np.max(np.abs(final_loop[:1 + model.nq + model.nv] - final_rollout[:1 + model.nq + model.nv])))

    sim = n_total * step
    return {
        "engine": "mujoco",
        "version": mujoco.__version__,
        "contact_law": (f"soft constraint solref=({timeconst:g} s, dampratio {dampratio:g}) "
                        f"solimp=(0.9,0.95,0.001,0.5,2), elliptic cone mu={MU}, condim 3, box-box"),
        "drive": ("mocap tube, pos set per step (solver sees wall velocity 0)" if drive_mode == "mocap"
                  else "tube fixed, inertial force -m*a(t) on cube (accelerating frame)"),
        "integrator": "Euler (semi-implicit), Newton solver",
        "step_s": step,
        "simulated_s": sim,
        "wall_s": wall,
        "real_time_factor": sim / wall,
        "steps_per_s": n_total / wall,
        "cpu_s": cpu,
        "real_time_factor_cpu": sim / cpu,
        "mean_normal_force_n": sum_n / n_win,
        "mean_normal_slip_power_w": sum_p / n_win,
        "settle_s": settle,
        "window_s": window,
        "cube_mass_kg": mass,
        "timing": f"mujoco.rollout C loop, best of {repeats}: " + ", ".join(f"{w:.3f}" for w in walls) + " s",
        "python_metrics_loop_wall_s": loop_wall,
        "max_penetration_m": max_pen,
        "max_contacts": max_contacts,
        "rollout_vs_loop_max_state_dev": dev,
    }


# ----------------------------------------------------------------------------------------------
# Drake
# ----------------------------------------------------------------------------------------------
def run_drake(step, settle, window, modulus, hc_diss, approx, repeats):
    import pydrake
    from pydrake.geometry import (AddCompliantHydroelasticProperties, AddContactMaterial,
                                  AddRigidHydroelasticProperties, Box, ProximityProperties)
    from pydrake.math import RigidTransform
    from pydrake.multibody.plant import (AddMultibodyPlant, CoulombFriction, MultibodyPlantConfig)
    from pydrake.multibody.tree import SpatialInertia, UnitInertia
    from pydrake.systems.analysis import Simulator
    from pydrake.systems.framework import DiagramBuilder, InputPortIndex
    from pydrake.systems.primitives import ConstantVectorSource, PortSwitch, Sine

    try:
        version = pydrake.version.version
    except AttributeError:
        from importlib.metadata import version as _v
        version = _v("drake")

    builder = DiagramBuilder()
    cfg = MultibodyPlantConfig(time_step=step, discrete_contact_approximation=approx,
                               contact_model="hydroelastic_with_fallback")
    plant, sg = AddMultibodyPlant(cfg, builder)
    plant.mutable_gravity_field().set_gravity_vector([0.0, -GRAVITY, 0.0])

    c = CUBE_SIDE / 2
    mass = RHO * CUBE_SIDE**3
    M = SpatialInertia(mass, [0, 0, 0], UnitInertia.SolidBox(CUBE_SIDE, CUBE_SIDE, CUBE_SIDE))
    cube = plant.AddRigidBody("cube", M)
    friction = CoulombFriction(MU, MU)

    cprops = ProximityProperties()
    AddContactMaterial(dissipation=hc_diss, friction=friction, properties=cprops)
    AddCompliantHydroelasticProperties(resolution_hint=CUBE_SIDE / 2, hydroelastic_modulus=modulus,
                                       properties=cprops)
    plant.RegisterCollisionGeometry(cube, RigidTransform(), Box(CUBE_SIDE, CUBE_SIDE, CUBE_SIDE),
                                    "cube", cprops)

    h = TUBE_INNER / 2
    t2 = WALL_T / 2
    lz = TUBE_LEN / 2
    outer = h + WALL_T
    walls = [
        ("floor", (0, -(h + t2), 0), (outer, t2, lz + WALL_T)),
        ("ceiling", (0, h + t2, 0), (outer, t2, lz + WALL_T)),
        ("wall_px", (h + t2, 0, 0), (t2, outer, lz + WALL_T)),
        ("wall_nx", (-(h + t2), 0, 0), (t2, outer, lz + WALL_T)),
        ("cap_pz", (0, 0, lz + t2), (outer, outer, t2)),
        ("cap_nz", (0, 0, -(lz + t2)), (outer, outer, t2)),
    ]
    for name, p, s in walls:
        wprops = ProximityProperties()
        AddContactMaterial(dissipation=hc_diss, friction=friction, properties=wprops)
        AddRigidHydroelasticProperties(properties=wprops)
        plant.RegisterCollisionGeometry(plant.world_body(), RigidTransform(list(p)),
                                        Box(2 * s[0], 2 * s[1], 2 * s[2]), name, wprops)
    plant.Finalize()
    nv = plant.num_velocities()
    # floating body velocities: [w_WB (3), v_WB (3)] in world -> x translation is index 3
    vx_index = cube.floating_velocities_start_in_v() + 3

    A = PEAK_G * G0
    w = 2.0 * math.pi * FREQ_HZ
    amp = np.zeros(nv)
    amp[vx_index] = -mass * A
    # settle is 20 whole periods at 20 Hz, so sin(w t) == sin(w (t - settle)) in the window
    if abs(settle * FREQ_HZ - round(settle * FREQ_HZ)) > 1e-9:
        raise ValueError("drake path needs settle to be a whole number of drive periods")
    sine = builder.AddSystem(Sine(amp, np.full(nv, w), np.zeros(nv)))
    zero = builder.AddSystem(ConstantVectorSource(np.zeros(nv)))
    switch = builder.AddSystem(PortSwitch(nv))
    p_zero = switch.DeclareInputPort("zero")
    p_sine = switch.DeclareInputPort("sine")
    builder.Connect(zero.get_output_port(), p_zero)
    builder.Connect(sine.get_output_port(0), p_sine)
    builder.Connect(switch.get_output_port(), plant.get_applied_generalized_force_input_port())
    diagram = builder.Build()

    def fresh():
        sim = Simulator(diagram)
        ctx = sim.get_mutable_context()
        pctx = plant.GetMyMutableContextFromRoot(ctx)
        sctx = switch.GetMyMutableContextFromRoot(ctx)
        X = RigidTransform([0.0, -h + c + 0.001, 0.0])
        plant.SetFreeBodyPose(pctx, cube, X)
        switch.get_port_selector_input_port().FixValue(sctx, p_zero.get_index())
        sim.Initialize()
        return sim, ctx, pctx, sctx

    n_settle = int(round(settle / step))
    n_win = int(round(window / step))
    t_end = (n_settle + n_win) * step

    # ---- timing pass: Simulator.AdvanceTo, all in C++ ----
    walls_t = []
    cpus = []
    for _ in range(repeats):
        sim, ctx, pctx, sctx = fresh()
        c0 = time.process_time()
        t0 = time.perf_counter()
        sim.AdvanceTo(n_settle * step)
        switch.get_port_selector_input_port().FixValue(sctx, p_sine.get_index())
        sim.AdvanceTo(t_end)
        walls_t.append(time.perf_counter() - t0)
        cpus.append(time.process_time() - c0)
    wall = min(walls_t)
    cpu = min(cpus)
    q_timing = plant.GetPositions(pctx).copy()

    # ---- metrics pass: step by step, read ContactResults after each step ----
    sim, ctx, pctx, sctx = fresh()
    sim.AdvanceTo(n_settle * step)
    switch.get_port_selector_input_port().FixValue(sctx, p_sine.get_index())
    cr_port = plant.get_contact_results_output_port()
    sum_n = 0.0
    sum_pe = 0.0
    sum_p = 0.0
    n_point = 0
    loop_t0 = time.perf_counter()
    for k in range(1, n_win + 1):
        sim.AdvanceTo((n_settle + k) * step)
        cr = cr_port.Eval(pctx)
        # sampled output ports (Drake default): the contact results are those of the step just taken
        # (start-of-step geometry); the context holds the end-of-step velocity v_{n+1}
        X_WB = plant.EvalBodyPoseInWorld(pctx, cube)
        V_WB = plant.EvalBodySpatialVelocityInWorld(pctx, cube)
        p_WB = X_WB.translation().tolist()
        w_W = V_WB.rotational().tolist()
        v_W = V_WB.translational().tolist()
        for i in range(cr.num_hydroelastic_contacts()):
            info = cr.hydroelastic_contact_info(i)
            surf = info.contact_surface()
            field = surf.poly_e_MN()
            n_mean = sum(surf.face_normal(f) * surf.area(f) for f in range(surf.num_faces()))
            n_mean = n_mean / max(np.linalg.norm(n_mean), 1e-30)
            fn_patch = abs(float(np.dot(info.F_Ac_W().translational(), n_mean)))
            # per polygon face: elastic pressure at its centroid times its area, rescaled so the faces
            # add up to the patch's normal force (which includes the Hunt-Crossley factor); slip =
            # tangential velocity of the cube's material point at the face centroid (walls are static)
            faces = []
            pe_sum = 0.0
            for f in range(surf.num_faces()):
                pc = surf.centroid(f)
                pe = max(0.0, float(field.EvaluateCartesian(f, pc))) * surf.area(f)
                nrm = surf.face_normal(f).tolist()
                r = (pc[0] - p_WB[0], pc[1] - p_WB[1], pc[2] - p_WB[2])
                faces.append((pe, slip_speed(v_W, w_W, r, nrm)))
                pe_sum += pe
            sum_n += fn_patch
            sum_pe += pe_sum
            if pe_sum > 0.0:
                sum_p += fn_patch * sum(pe * vt for pe, vt in faces) / pe_sum
        for i in range(cr.num_point_pair_contacts()):
            info = cr.point_pair_contact_info(i)
            n_point += 1
            fn = abs(float(np.dot(info.contact_force(), info.point_pair().nhat_BA_W)))
            sum_n += fn
            sum_p += fn * abs(float(info.slip_speed()))
    loop_wall = time.perf_counter() - loop_t0
    dev = float(np.max(np.abs(plant.GetPositions(pctx) - q_timing)))

    simulated = t_end
    n_total = n_settle + n_win
    return {
        "engine": "drake",
        "version": version,
        "contact_law": (f"hydroelastic (compliant cube E_h={modulus:g} Pa, rigid walls), Hunt-Crossley "
                        f"d={hc_diss:g} s/m, mu={MU}; discrete '{approx}' approximation"),
        "drive": "tube fixed, inertial force -m*a(t) on cube (accelerating frame)",
        "integrator": f"MultibodyPlant discrete, time_step {step:g}",
        "step_s": step,
        "simulated_s": simulated,
        "wall_s": wall,
        "real_time_factor": simulated / wall,
        "steps_per_s": n_total / wall,
        "cpu_s": cpu,
        "real_time_factor_cpu": simulated / cpu,
        "mean_normal_force_n": sum_n / n_win,
        "mean_normal_slip_power_w": sum_p / n_win,
        "settle_s": settle,
        "window_s": window,
        "cube_mass_kg": mass,
        "timing": f"Simulator.AdvanceTo C++ loop, best of {repeats}: " + ", ".join(f"{x:.3f}" for x in walls_t) + " s",
        "python_metrics_loop_wall_s": loop_wall,
        "point_contact_fallbacks": n_point,
        "mean_elastic_pressure_force_n": sum_pe / n_win,
        "timing_vs_metrics_max_q_dev": dev,
    }


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--window", type=float, default=5.0, help="excitation window, s (default 5)")
    ap.add_argument("--settle", type=float, default=1.0, help="settle with no input, s (default 1)")
    ap.add_argument("--steps", default="5e-5,1e-4", help="MuJoCo time steps, comma separated")
    ap.add_argument("--no-mocap", action="store_true",
                    help="skip the mocap-driven MuJoCo variant (run at the first step only)")
    ap.add_argument("--timeconst", type=float, default=0.001, help="MuJoCo solref time constant, s")
    ap.add_argument("--dampratio", type=float, default=1.0, help="MuJoCo solref damping ratio")
    ap.add_argument("--drake-steps", default="1e-4", help="Drake time steps, comma separated ('' or none = skip)")
    ap.add_argument("--drake-modulus", type=float, default=1e8, help="hydroelastic modulus of the cube, Pa")
    ap.add_argument("--drake-hc", type=float, default=50.0, help="Hunt-Crossley dissipation, s/m")
    ap.add_argument("--drake-approx", default="lagged", help="discrete contact approximation")
    ap.add_argument("--repeats", type=int, default=3, help="MuJoCo timing repeats (best is reported)")
    ap.add_argument("--inner-side-in", type=float, default=1.25,
                    help="tube inner side, in (thesis Table 5.1: A 2.0, B 1.5, C 1.25, D 1.125)")
    args = ap.parse_args()
    global TUBE_INNER
    TUBE_INNER = args.inner_side_in * 0.0254

    core = pin_one_core()
    log(f"pinned to core {core}" if core is not None else "could not pin to one core")

    for step in [float(s) for s in args.steps.split(",") if s.strip()]:
        log(f"mujoco step {step:g} ...")
        print(json.dumps(run_mujoco(step, args.settle, args.window, "frame", args.timeconst,
                                    args.dampratio, args.repeats)), flush=True)
    if not args.no_mocap:
        step = float(args.steps.split(",")[0])
        log(f"mujoco (mocap drive) step {step:g} ...")
        print(json.dumps(run_mujoco(step, args.settle, args.window, "mocap", args.timeconst,
                                    args.dampratio, args.repeats)), flush=True)

    skip = args.drake_steps.strip() in ("", "none", "''")
    dsteps = [] if skip else [float(s) for s in args.drake_steps.split(",") if s.strip()]
    if dsteps:
        try:
            import pydrake  # noqa: F401
            import pydrake.multibody.plant  # noqa: F401
        except Exception as e:  # not installed, or fails to import (missing system libraries)
            print(json.dumps({"engine": "drake", "status": "unavailable",
                              "reason": f"{type(e).__name__}: {e}"}), flush=True)
            return
        for step in dsteps:
            log(f"drake step {step:g} ...")
            try:
                row = run_drake(step, args.settle, args.window, args.drake_modulus, args.drake_hc,
                                args.drake_approx, 1)
            except Exception as e:
                row = {"engine": "drake", "status": "failed", "step_s": step,
                       "reason": f"{type(e).__name__}: {e}"}
            print(json.dumps(row), flush=True)


if __name__ == "__main__":
    main()
