#!/usr/bin/python3
"""SB-1 against CalculiX: the same tetrahedral mesh, loads and time steps in both codes.

What it models: the SB-1 spindle box under duty cycle P-1 (cases/sb1.toml), meshed once by
thermotwin; the mesh, materials, films, bearing heat and duty cycle are written as a CalculiX
input deck, and both codes integrate the same transient with backward Euler and equal steps.

  thermal   order-1 mesh (C3D4): temperatures at T01..T54 and the TCP at every step, max |dT|
            against 0.05 K, and the wall time of the whole ccx run over thermotwin's thermal
            stage (assembly + factorisations + back-substitutions).
  elastic   order-2 mesh (C3D10) or order 1 (--elastic-order 1): ccx heat transfer on that mesh,
            then a *STATIC job per chosen time reading ccx's own temperatures from its .frd;
            TCP dx, dy, dz against thermotwin's thermal_error.csv, tolerance
            max(3 % of the largest component, 0.5 um) per time.

How to run (from the repository root; writes only under bench/work/calculix):
  /usr/bin/python3 bench/calculix/run_bench.py [--step 300] [--threads 1] [--skip-elastic]
      [--elastic-order 2] [--thermotwin build-int/thermotwin]
Needs ccx (Debian calculix-ccx) and python3-vtk9 (scripts/setup.sh --with-calculix).
Writes bench/work/calculix/{thermal,elastic}/... and prints a summary; exit status 1 when a
tolerance is missed.
"""

import argparse
import json
import os
import re
import resource
import shutil
import subprocess
import sys
import time
import tomllib
from pathlib import Path

import numpy as np
import vtk
from vtk.util.numpy_support import vtk_to_numpy

ROOT = Path(__file__).resolve().parents[2]
WORK = ROOT / "bench" / "work" / "calculix"
SWITCH_HAIR_S = 1e-3  # gap between the two amplitude points of an on/off switch [s]
# ccx reads at most 20 characters per number: coordinates with 12 significant digits.
# Local faces of a tet in ccx's numbering F1..F4 (0-based corner indices; same for C3D10).
CCX_TET_FACES = ((0, 1, 2), (0, 3, 1), (1, 3, 2), (2, 3, 0))


# ---------------------------------------------------------------------------------------------
# 1. Case variants and the mesh as thermotwin wrote it
# ---------------------------------------------------------------------------------------------
def variant_case(base: Path, out: Path, order: int, step_s: float, fields_interval_s=None) -> Path:
    """The case with another mesh order and step; outputs at every step so times line up."""
    text = base.read_text()
    subs = [(r"(?m)^order\s*=.*$", f"order = {order}"),
            (r"(?m)^step_s\s*=.*$", f"step_s = {step_s!r}"),
            (r"(?m)^output_interval_s\s*=.*$", f"output_interval_s = {step_s!r}"),
            (r"(?m)^scheme\s*=.*$", 'scheme = "backward_euler"')]
    for pattern, repl in subs:
        text, n = re.subn(pattern, repl, text)
        if n != 1:
            sys.exit(f"run_bench: expected one match of {pattern} in {base}, found {n}")
    fields = "true" if fields_interval_s else "false"
    extra = f"fields = {fields}\n" + (f"fields_interval_s = {fields_interval_s!r}\n" if fields_interval_s else "")
    text, n = re.subn(r"(?m)^\[outputs\]\s*$", "[outputs]\n" + extra, text)
    if n != 1:
        sys.exit(f"run_bench: no [outputs] table in {base}")
    out.parent.mkdir(parents=True, exist_ok=True)
    out.write_text(text)
    return out


def read_mesh(mesh_dir: Path) -> dict:
    """Nodes [m], tets (0-based, VTK order), region per tet, boundary faces with their group."""
    r = vtk.vtkXMLUnstructuredGridReader()
    r.SetFileName(str(mesh_dir / "mesh.vtu"))
    r.Update()
    g = r.GetOutput()
    nodes = vtk_to_numpy(g.GetPoints().GetData()).astype(float)
    conn = vtk_to_numpy(g.GetCells().GetConnectivityArray()).astype(np.int64)
    ncell = g.GetNumberOfCells()
    tets = conn.reshape(ncell, -1)
    region = vtk_to_numpy(g.GetCellData().GetArray("region")).astype(int)
    names_arr = g.GetFieldData().GetAbstractArray("region_names")
    region_names = [names_arr.GetValue(i) for i in range(names_arr.GetNumberOfValues())]

    r = vtk.vtkXMLPolyDataReader()
    r.SetFileName(str(mesh_dir / "boundary.vtp"))
    r.Update()
    p = r.GetOutput()
    node_of = vtk_to_numpy(p.GetPointData().GetArray("node")).astype(np.int64)
    pconn = vtk_to_numpy(p.GetPolys().GetConnectivityArray()).astype(np.int64)
    faces = node_of[pconn.reshape(p.GetNumberOfCells(), -1)]
    group = vtk_to_numpy(p.GetCellData().GetArray("group_id")).astype(int)
    interface = vtk_to_numpy(p.GetCellData().GetArray("interface")).astype(int)
    gn = p.GetFieldData().GetAbstractArray("group_names")
    group_names = [gn.GetValue(i) for i in range(gn.GetNumberOfValues())]
    report = json.loads((mesh_dir / "mesh_report.json").read_text())
    return dict(nodes=nodes, tets=tets, region=region, region_names=region_names, faces=faces,
                face_group=group, face_interface=interface, group_names=group_names, report=report)


def face_elements(mesh: dict, group: int):
    """(element index 0-based, ccx face number 1..4) of every exterior face of `group`."""
    corners = mesh["tets"][:, :4]
    lookup = {}
    for f, (a, b, c) in enumerate(CCX_TET_FACES):
        keys = np.sort(corners[:, [a, b, c]], axis=1)
        for e, k in enumerate(map(tuple, keys)):
            lookup.setdefault(k, []).append((e, f + 1))
    sel = np.nonzero((mesh["face_group"] == group) & (mesh["face_interface"] == 0))[0]
    out = []
    for fi in sel:
        hits = lookup.get(tuple(sorted(mesh["faces"][fi, :3])), [])
        if len(hits) != 1:
            sys.exit(f"run_bench: boundary face {fi} bounds {len(hits)} tets, expected 1")
        out.append(hits[0])
    return out


# ---------------------------------------------------------------------------------------------
# 2. The CalculiX deck
# ---------------------------------------------------------------------------------------------
def speed_segments(case: dict):
    """[(start, end, speed_rpm)] of the duty cycle."""
    dc = case["duty_cycle"]
    segs = sorted(dc["segments"], key=lambda s: s["start_s"])
    ends = [s["start_s"] for s in segs[1:]] + [dc["end_s"]]
    return [(s["start_s"], e, s["speed_rpm"]) for s, e in zip(segs, ends)]


def source_power_w(src: dict, speed: float) -> float:
    if src["law"] != "speed_power":
        sys.exit(f"run_bench: heat source law {src['law']!r} not supported (only speed_power)")
    if speed <= 0:
        return 0.0
    return src["power_ref_W"] * (speed / src["ref_speed_rpm"]) ** src["exponent"]


def amplitude_points(segments, value_of):
    """Piecewise constant in time, as ccx's linear table: two points a hair apart at a switch."""
    pts = []
    for i, (t0, t1, n) in enumerate(segments):
        v = value_of(n)
        pts.append((t0 if i == 0 else t0 + SWITCH_HAIR_S, v))
        pts.append((t1, v))
    return pts


def deck_mesh(mesh: dict, case: dict, element: str) -> list:
    """Nodes, elements per region, materials and sections: the part shared by all jobs."""
    L = ["*HEADING", f"SB-1 from thermotwin's mesh ({element})", "*NODE, NSET=NALL"]
    L += [f"{i + 1}, {x:.12g}, {y:.12g}, {z:.12g}" for i, (x, y, z) in enumerate(mesh["nodes"])]
    bodies = {b["name"]: b for b in case["bodies"]}
    for rid, rname in enumerate(mesh["region_names"]):
        L.append(f"*ELEMENT, TYPE={element}, ELSET=E_{rname}")
        for e in np.nonzero(mesh["region"] == rid)[0]:
            L.append(f"{e + 1}, " + ", ".join(str(n + 1) for n in mesh["tets"][e]))
    for rname in mesh["region_names"]:
        L.append(f"*SOLID SECTION, ELSET=E_{rname}, MATERIAL={bodies[rname]['material']}")
    for name, m in case["materials"].items():
        L += [f"*MATERIAL, NAME={name}",
              "*CONDUCTIVITY", f"{m['conductivity_W_mK']!r}",
              "*SPECIFIC HEAT", f"{m['specific_heat_J_kgK']!r}",
              "*DENSITY", f"{m['density_kg_m3']!r}",
              "*ELASTIC", f"{m['youngs_modulus_Pa']!r}, {m['poisson_ratio']!r}",
              f"*EXPANSION, ZERO={case['mechanical']['reference_temperature_degC']!r}",
              f"{m['expansion_per_K']!r}"]
    return L


def point_nodes(mesh: dict, ids) -> dict:
    """Mesh node (0-based) of each named point."""
    by_id = {p["id"]: p["node"] for p in mesh["report"]["points"]}
    return {i: by_id[i] for i in ids}


def thermal_deck(mesh: dict, case: dict, element: str, step_s: float, points: dict, step_ends=None,
                 window=None) -> str:
    """The transient as one *STEP printing NT at the points every increment, or, with `step_ends`,
    one *STEP per interval ending there, each writing all nodes' NT to the .frd at its end only
    (ccx's *TEMPERATURE, FILE= picks a result by step number, BSTEP). With `window` =
    (start, end, nodal temperatures at start [degC]) only that interval, ccx's time 0 = start."""
    L = deck_mesh(mesh, case, element)
    L += ["*NSET, NSET=NPOINTS"] + [str(n + 1) for n in sorted(set(points.values()))]
    start = window[0] if window else 0.0
    segments = [(max(a, start) - start, b - start, n) for a, b, n in speed_segments(case) if b > start]
    vol = {name: b["volume_m3"] for name, b in mesh["report"]["bodies"].items()}
    dflux = []
    for k, src in enumerate(case["thermal"]["heat_sources"]):
        p_max = max(source_power_w(src, n) for _, _, n in segments)
        L.append(f"*AMPLITUDE, NAME=A{k}, TIME=TOTAL TIME")
        L += [f"{t!r}, {v!r}" for t, v in amplitude_points(segments, lambda n: source_power_w(src, n) / p_max)]
        dflux += [f"*DFLUX, AMPLITUDE=A{k}", f"E_{src['body']}, BF, {p_max / vol[src['body']]!r}"]
    t0 = case["thermal"]["initial_temperature_degC"]
    end = (window[1] if window else case["duty_cycle"]["end_s"]) - start
    L += ["*INITIAL CONDITIONS, TYPE=TEMPERATURE"]
    L += [f"{n + 1}, {t:.10g}" for n, t in enumerate(window[2])] if window else [f"NALL, {t0!r}"]
    ends = list(step_ends) if step_ends else [end]
    incs = [int(round((b - a) / step_s)) for a, b in zip([0.0] + ends[:-1], ends)]
    L += [f"*STEP, INC={incs[0] + 10}", "*HEAT TRANSFER, DIRECT", f"{step_s!r}, {ends[0]!r}"]
    for conv in case["thermal"]["convection"]:
        if "h_W_m2K" not in conv or "sink_degC" not in conv:
            sys.exit(f"run_bench: convection {conv} must have constant h_W_m2K and sink_degC")
        gid = mesh["group_names"].index(conv["group"])
        L.append("*FILM")
        for e, f in face_elements(mesh, gid):
            L.append(f"{e + 1}, F{f}, {conv['sink_degC']!r}, {conv['h_W_m2K']!r}")
    L += dflux  # films and fluxes stay active in the later steps
    for k, (a, b) in enumerate(zip([0.0] + ends[:-1], ends)):
        if k > 0:
            L += [f"*STEP, INC={incs[k] + 10}", "*HEAT TRANSFER, DIRECT", f"{step_s!r}, {b - a!r}"]
        freq = incs[k] if step_ends else 1
        L += [f"*NODE PRINT, NSET=NPOINTS, FREQUENCY={freq}", "NT"]
        if step_ends:
            L += [f"*NODE FILE, FREQUENCY={freq}", "NT"]
        L.append("*END STEP")
    L.append("")
    return "\n".join(L)


def static_deck(mesh: dict, case: dict, element: str, temperatures, points: dict, solver=None) -> str:
    """One *STATIC step per entry of `temperatures`: either the number of a result block of the
    heat-transfer job's ht.frd (ccx's own temperatures) or a vector of nodal temperatures [degC]."""
    L = deck_mesh(mesh, case, element)
    L += ["*NSET, NSET=NPOINTS"] + [str(n + 1) for n in sorted(set(points.values()))]
    fixed = set()
    for gname in case["mechanical"]["fixed"]:
        gid = mesh["group_names"].index(gname)
        sel = (mesh["face_group"] == gid) & (mesh["face_interface"] == 0)
        fixed.update(int(n) for n in mesh["faces"][sel].ravel())
    L += ["*NSET, NSET=NFIXED"] + [str(n + 1) for n in sorted(fixed)]
    L += ["*BOUNDARY", "NFIXED, 1, 3, 0."]
    t_ref = case["mechanical"]["reference_temperature_degC"]
    L += ["*INITIAL CONDITIONS, TYPE=TEMPERATURE", f"NALL, {t_ref!r}"]
    for temps in temperatures:
        L += ["*STEP", "*STATIC" + (f", SOLVER={solver}" if solver else "")]
        if np.isscalar(temps):
            L.append(f"*TEMPERATURE, FILE=ht.frd, BSTEP={int(temps)}")
        else:
            L.append("*TEMPERATURE")
            L += [f"{n + 1}, {t:.10g}" for n, t in enumerate(temps)]
        L += ["*NODE PRINT, NSET=NPOINTS", "U, NT", "*END STEP"]
    L.append("")
    return "\n".join(L)


# ---------------------------------------------------------------------------------------------
# 3. Running and reading results
# ---------------------------------------------------------------------------------------------
def children_cpu_s() -> float:
    ru = resource.getrusage(resource.RUSAGE_CHILDREN)
    return ru.ru_utime + ru.ru_stime


def run_ccx(job_dir: Path, job: str, threads: int, cpu: dict = None) -> float:
    """Wall time of one ccx job [s]; its CPU time goes to cpu[job] when given."""
    env = dict(os.environ, OMP_NUM_THREADS=str(threads), CCX_NPROC_EQUATION_SOLVER=str(threads))
    c0 = children_cpu_s()
    t0 = time.perf_counter()
    with open(job_dir / f"{job}.log", "w") as log:
        rc = subprocess.run(["ccx", "-i", job], cwd=job_dir, env=env, stdout=log, stderr=subprocess.STDOUT).returncode
    wall = time.perf_counter() - t0
    if cpu is not None:
        cpu[job] = children_cpu_s() - c0
    text = (job_dir / f"{job}.log").read_text(errors="replace")
    if rc != 0 or "*ERROR" in text:
        sys.exit(f"run_bench: ccx {job} failed (rc {rc}); see {job_dir / (job + '.log')}")
    return wall


def run_thermotwin(exe: Path, case: Path, out: Path, threads: int) -> dict:
    if out.exists():
        shutil.rmtree(out)
    env = dict(os.environ, OMP_NUM_THREADS=str(threads), TT_BLAS_THREADS="1")
    c0 = children_cpu_s()
    t0 = time.perf_counter()
    subprocess.run([str(exe), "run", str(case), "--out", str(out), "--quiet"], check=True, env=env)
    summary = json.loads((out / "summary.json").read_text())
    summary["wall_s"] = time.perf_counter() - t0
    summary["cpu_s"] = children_cpu_s() - c0
    return summary


def read_dat_blocks(dat: Path, quantity: str) -> list:
    """[(time, {node 1-based: values})] for every block `<quantity> ... and time t` of a .dat."""
    blocks, cur = [], None
    head = re.compile(rf"^\s*{quantity}\b.*\band time\s+(\S+)")
    for line in dat.read_text().splitlines():
        m = head.match(line)
        if m:
            cur = {}
            blocks.append((float(m.group(1)), cur))
            continue
        parts = line.split()
        if cur is not None and parts and parts[0].isdigit():
            cur[int(parts[0])] = [float(v) for v in parts[1:]]
        elif cur is not None and parts and cur:
            cur = None
    return blocks


def read_csv(path: Path):
    header = path.read_text().splitlines()[0].split(",")
    data = np.loadtxt(path, delimiter=",", skiprows=1, ndmin=2)
    return header, data


def ccx_temperatures(dat: Path, points: dict, ids):
    """times [s], #times x #ids temperatures [degC] from *NODE PRINT NT."""
    blocks = read_dat_blocks(dat, "temperatures")
    times = np.array([t for t, _ in blocks])
    temps = np.array([[b[points[i] + 1][0] for i in ids] for _, b in blocks])
    return times, temps


def tt_columns(path: Path, names):
    header, data = read_csv(path)
    return data[:, 0], data[:, [header.index(n) for n in names]]


def common_rows(t_a, t_b):
    """Index pairs of equal times (to 1e-6 s)."""
    pairs = [(i, int(np.argmin(np.abs(t_b - t)))) for i, t in enumerate(t_a)]
    return [(i, j) for i, j in pairs if abs(t_b[j] - t_a[i]) < 1e-6]


def lscpu_line() -> str:
    out = subprocess.run(["lscpu"], capture_output=True, text=True).stdout
    model = re.search(r"Model name:\s*(.*)", out).group(1).strip()
    cpus = re.search(r"^CPU\(s\):\s*(\d+)", out, re.M).group(1)
    l3 = re.search(r"L3 cache:\s*(.*)", out)
    mem_kb = int(re.search(r"MemTotal:\s*(\d+)", Path("/proc/meminfo").read_text()).group(1))
    return f"{model}, {cpus} CPUs, L3 {l3.group(1).strip() if l3 else '?'}, {mem_kb / 2**20:.1f} GiB RAM"


# ---------------------------------------------------------------------------------------------
# 4. The two comparisons
# ---------------------------------------------------------------------------------------------
def thermal_comparison(args, case: dict) -> dict:
    """Whole duty cycle, or with args.window = (start, end) only that interval in ccx, started
    from thermotwin's nodal temperatures at `start` (for steps too small for a whole ccx run)."""
    w = args.window
    d = WORK / ("thermal" if not w else f"thermal_dt{args.step:g}_{w[0]:g}-{w[1]:g}")
    d.mkdir(parents=True, exist_ok=True)
    case_file = variant_case(args.case, d / "sb1_o1.toml", 1, args.step, fields_interval_s=w[0] if w else None)
    if not (d / "mesh").exists() or args.remesh:
        subprocess.run([str(args.thermotwin), "mesh", str(case_file), "--out", str(d / "mesh")], check=True,
                       stderr=subprocess.DEVNULL)
    mesh = read_mesh(d / "mesh")
    ids = [f"T{i:02d}" for i in range(1, 55)] + [case["mechanical"]["tcp"]]
    points = point_nodes(mesh, ids)
    print(f"thermal: {len(mesh['nodes'])} nodes, {len(mesh['tets'])} C3D4, dt = {args.step} s, "
          f"window {w}", flush=True)
    # Timing: each code `repeats` times, the fastest run counts (the machine is shared).
    runs, ccx_runs = [], []
    for r in range(args.repeats):
        runs.append(run_thermotwin(args.thermotwin, case_file, d / "tt", args.threads))
        if r == 0:
            window = (w[0], w[1], thermotwin_fields(d / "tt", [w[0]])[0]) if w else None
            (d / "ht.inp").write_text(thermal_deck(mesh, case, "C3D4", args.step, points, window=window))
        cpu = {}
        ccx_runs.append((run_ccx(d, "ht", args.threads, cpu), cpu["ht"]))
    stage = lambda s: sum(s["timings"][k] for k in ("thermal_assemble_s", "thermal_factor_s", "thermal_solve_s"))
    summary = min(runs, key=stage)
    ccx_wall, ccx_cpu = min(ccx_runs)
    t_ccx, temp_ccx = ccx_temperatures(d / "ht.dat", points, ids)
    t_ccx = t_ccx + (w[0] if w else 0.0)
    t_tt, temp_tt = tt_columns(d / "tt" / "temperatures.csv", [i + "_degC" for i in ids])
    rows = common_rows(t_tt, t_ccx)
    diff = np.array([temp_tt[i] - temp_ccx[j] for i, j in rows])
    rise = np.array([temp_tt[i] for i, _ in rows]) - case["thermal"]["initial_temperature_degC"]
    k, c = np.unravel_index(np.argmax(np.abs(diff)), diff.shape)
    tm = summary["timings"]
    tt_thermal = tm["thermal_assemble_s"] + tm["thermal_factor_s"] + tm["thermal_solve_s"]
    res = dict(nodes=len(mesh["nodes"]), tets=len(mesh["tets"]), step_s=args.step, increments=len(t_ccx),
               window_s=list(w) if w else None, ccx_wall_per_increment_s=ccx_wall / len(t_ccx),
               tt_thermal_per_step_s=tt_thermal / summary["steps"],
               compared_times=len(rows), max_abs_dT_K=float(np.abs(diff).max()),
               max_abs_dT_at=dict(time_s=float(t_tt[rows[k][0]]), point=ids[c]),
               max_abs_dT_sensors_K=float(np.abs(diff[:, :54]).max()),
               max_abs_dT_tcp_K=float(np.abs(diff[:, 54]).max()),
               max_rise_K=float(rise.max()), ccx_wall_s=ccx_wall, ccx_cpu_s=ccx_cpu, tt_thermal_s=tt_thermal,
               tt_process_cpu_s=summary["cpu_s"], tt_process_wall_s=summary["wall_s"],
               tt_thermal_s_all=[stage(s) for s in runs], ccx_wall_s_all=[w for w, _ in ccx_runs],
               tt_timings=tm, tt_steps=summary["steps"], threads=args.threads, repeats=args.repeats,
               # a window compares per step: ccx ran only part of the cycle
               ratio=(ccx_wall / len(t_ccx)) / (tt_thermal / summary["steps"]) if w else ccx_wall / tt_thermal, ok=bool(np.abs(diff).max() <= 0.05))
    np.savetxt(d / "dT.csv", np.column_stack([[t_tt[i] for i, _ in rows], diff]), delimiter=",",
               header="time_s," + ",".join(i + "_dT_K" for i in ids), comments="", fmt="%.6g")
    return res


def thermotwin_fields(series_dir: Path, times) -> list:
    """Nodal temperatures [degC] of thermotwin's fields.pvd at each of `times`."""
    text = (series_dir / "fields.pvd").read_text()
    files = {float(t): f for t, f in re.findall(r'timestep="([^"]+)"[^>]*file="([^"]+)"', text)}
    out = []
    for t in times:
        key = min(files, key=lambda k: abs(k - t))
        if abs(key - t) > 1e-6:
            sys.exit(f"run_bench: thermotwin wrote no field at t = {t} s")
        r = vtk.vtkXMLUnstructuredGridReader()
        r.SetFileName(str(series_dir / files[key]))
        r.Update()
        out.append(vtk_to_numpy(r.GetOutput().GetPointData().GetArray("temperature_degC")).astype(float))
    return out


def elastic_comparison(args, case: dict) -> dict:
    order = args.elastic_order
    element = "C3D10" if order == 2 else "C3D4"
    source = args.elastic_temperatures or ("thermotwin" if order == 2 else "ccx")
    d = WORK / f"elastic_o{order}_{source}"
    d.mkdir(parents=True, exist_ok=True)
    case_file = variant_case(args.case, d / f"sb1_o{order}.toml", order, args.step,
                             fields_interval_s=args.step if source == "thermotwin" else None)
    if not (d / "mesh").exists() or args.remesh:
        subprocess.run([str(args.thermotwin), "mesh", str(case_file), "--out", str(d / "mesh")], check=True,
                       stderr=subprocess.DEVNULL)
    mesh = read_mesh(d / "mesh")
    tcp = case["mechanical"]["tcp"]
    ids = [f"T{i:02d}" for i in range(1, 55)] + [tcp]
    points = point_nodes(mesh, ids)
    times = args.elastic_times
    incs = [int(round(t / args.step)) for t in times]
    print(f"elastic: {len(mesh['nodes'])} nodes, {len(mesh['tets'])} {element}, times {times}, "
          f"temperatures from {source}", flush=True)
    summary = run_thermotwin(args.thermotwin, case_file, d / "tt", args.threads)
    ht_wall, cpu = float("nan"), {}
    if source == "ccx":
        (d / "ht.inp").write_text(thermal_deck(mesh, case, element, args.step, points, step_ends=times))
        if not (args.reuse_ht and (d / "ht.frd").exists()):
            ht_wall = run_ccx(d, "ht", args.threads, cpu)
        t_ht, temp_ht = ccx_temperatures(d / "ht.dat", points, ids)
        temperatures = list(range(1, len(times) + 1))  # ht.frd's steps
    else:
        temperatures = thermotwin_fields(d / "tt", times)
        t_ht = np.array(times)
        temp_ht = np.array([[f[points[i]] for i in ids] for f in temperatures])
    (d / "st.inp").write_text(static_deck(mesh, case, element, temperatures, points, args.static_solver))
    st_wall = run_ccx(d, "st", args.threads, cpu)
    # The static job prints the NT it used: check them against the transient they came from.
    st_nt = read_dat_blocks(d / "st.dat", "temperatures")
    st_u = read_dat_blocks(d / "st.dat", "displacements")
    t_err, err = tt_columns(d / "tt" / "thermal_error.csv", ["dx_um", "dy_um", "dz_um"])
    t_tt, temp_tt = tt_columns(d / "tt" / "temperatures.csv", [i + "_degC" for i in ids])
    out = []
    for k, (t, inc) in enumerate(zip(times, incs)):
        read_nt = np.array([st_nt[k][1][points[i] + 1][0] for i in ids])
        own_nt = temp_ht[int(np.argmin(np.abs(t_ht - t)))]
        u_ccx = np.array(st_u[k][1][points[tcp] + 1][:3]) * 1e6
        u_tt = err[int(np.argmin(np.abs(t_err - t)))]
        dT = np.abs(temp_tt[int(np.argmin(np.abs(t_tt - t)))] - own_nt).max()
        tol = max(0.03 * np.abs(u_tt).max(), 0.5)
        out.append(dict(time_s=t, tcp_um_thermotwin=u_tt.tolist(), tcp_um_ccx=u_ccx.tolist(),
                        max_abs_diff_um=float(np.abs(u_tt - u_ccx).max()), tolerance_um=float(tol),
                        static_temperature_check_K=float(np.abs(read_nt - own_nt).max()),
                        max_abs_dT_points_K=float(dT), ok=bool(np.abs(u_tt - u_ccx).max() <= tol)))
    return dict(order=order, element=element, temperatures_from=source, nodes=len(mesh["nodes"]),
                tets=len(mesh["tets"]),
                static_solver=args.static_solver or "SPOOLES", step_s=args.step, ccx_heat_wall_s=ht_wall, ccx_static_wall_s=st_wall, ccx_cpu_s=cpu, threads=args.threads,
                tt_timings=summary["timings"], times=out, ok=all(o["ok"] for o in out))


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--case", type=Path, default=ROOT / "cases" / "sb1.toml")
    ap.add_argument("--thermotwin", type=Path, default=ROOT / "build-int" / "thermotwin")
    ap.add_argument("--step", type=float, default=300.0, help="time step of both codes [s]")
    ap.add_argument("--threads", type=int, default=1, help="OpenMP threads of both codes")
    ap.add_argument("--repeats", type=int, default=1, help="timing runs of the thermal comparison")
    ap.add_argument("--window", type=float, nargs=2, metavar=("START", "END"),
                    help="thermal: run ccx only over [START, END] s from thermotwin's field at START")
    ap.add_argument("--skip-thermal", action="store_true")
    ap.add_argument("--skip-elastic", action="store_true")
    ap.add_argument("--elastic-order", type=int, default=2, choices=(1, 2))
    ap.add_argument("--elastic-times", type=float, nargs="+", default=[600.0, 2100.0, 2400.0, 4800.0, 7200.0])
    ap.add_argument("--elastic-temperatures", choices=("ccx", "thermotwin"),
                    help="ccx: its own heat transfer on the same mesh, read from its .frd (default for "
                    "order 1); thermotwin: thermotwin's nodal temperatures as *TEMPERATURE cards "
                    "(default for order 2: ccx's C3D10 heat transfer takes ~4 min per increment here)")
    ap.add_argument("--static-solver", help="ccx *STATIC SOLVER= (default SPOOLES); 'ITERATIVE CHOLESKY' "
                    "finishes the order-2 (417k dof) steps where SPOOLES took too long on this machine")
    ap.add_argument("--reuse-ht", action="store_true", help="keep an existing elastic heat-transfer .frd")
    ap.add_argument("--remesh", action="store_true")
    args = ap.parse_args()
    args.case, args.thermotwin = args.case.resolve(), args.thermotwin.resolve()
    case = tomllib.loads(args.case.read_text())
    args.elastic_times = sorted(args.elastic_times)
    for t in args.elastic_times:
        if abs(t / args.step - round(t / args.step)) > 1e-9:
            sys.exit(f"run_bench: elastic time {t} s is not a multiple of the step {args.step} s")
    # result.json keeps the parts of earlier runs that this run does not redo.
    done = {}
    if not args.skip_thermal:
        done["thermal" if not args.window else "thermal_window"] = thermal_comparison(args, case)
    if not args.skip_elastic:
        r = elastic_comparison(args, case)
        done[f"elastic_o{r['order']}_{r['temperatures_from']}"] = r
    for key, r in done.items():
        r["load_average"] = os.getloadavg()
        print(key, json.dumps(r, indent=1), flush=True)
    result_file = WORK / "result.json"
    result = json.loads(result_file.read_text()) if result_file.exists() else {}
    result.update(date=time.strftime("%Y-%m-%d"), machine=lscpu_line(), ccx=shutil.which("ccx"))
    result.update(done)
    WORK.mkdir(parents=True, exist_ok=True)
    result_file.write_text(json.dumps(result, indent=1))
    ok = all(r["ok"] for r in done.values())
    print(f"run_bench: {'PASS' if ok else 'FAIL'} -> {WORK / 'result.json'}")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
