"""cellsph.Scene / cellsph.Simulation against the `cellsph run` program (same scene, same thread count:
same bits), checkpoints, read_frames, and the errors."""
import filecmp
import json
import os
import subprocess

import numpy as np
import pytest

import cellsph

FPS = 100  # frames every 0.01 s


def cli_run(binary, out, scene, until, threads=2, sets=(), formats="csv"):
    cmd = [binary, "run", scene, "--threads", str(threads), "--until", str(until), "--fps", str(FPS),
           "--format", formats, "--out", str(out), "--quiet"]
    for s in sets:
        cmd += ["--set", s]
    subprocess.run(cmd, check=True)
    with open(os.path.join(out, "frames.csv")) as f:
        return len(f.readlines()) - 1


def python_run(scene, out, frames, threads=2, formats="csv"):
    sim = cellsph.Simulation(scene, threads=threads)
    sim.write_frame(out, formats)
    for k in range(1, frames):
        sim.run_until(k * (1.0 / FPS))  # the frame times of `cellsph run`: k * (1 / fps)
        sim.write_frame(out, formats)
    return sim


@pytest.mark.parametrize(
    "scene, sets",
    [
        ("dam-break-2d", ()),  # 2D double, WCSPH, Adami walls
        ("dam-break-3d", ("/spacing=0.1",)),  # 3D float
        ("two-phase", ("/spacing=0.02",)),  # the paper's model: leap-frog, interface tension
        ("channel-inflow", ()),  # an emitter and a sink: counts change between frames
    ],
)
def test_same_bits_as_cellsph_run(cellsph_binary, tmp_path, scene, sets):
    formats = "vtu,ply,csv"
    frames = cli_run(cellsph_binary, tmp_path / "cli", scene, 0.03, sets=sets, formats=formats)
    assert frames == 4  # t = 0, 0.01, 0.02, 0.03
    s = cellsph.Scene.load(scene)
    for edit in sets:
        pointer, value = edit.split("=")
        s.set(pointer, json.loads(value))
    python_run(s, tmp_path / "py", frames, formats=formats)
    names = ["frames.csv", "particles.pvd"] + [f"frame_{k:05d}.{e}" for k in range(frames) for e in ("vtu", "ply", "csv")]
    match, mismatch, errors = filecmp.cmpfiles(tmp_path / "cli", tmp_path / "py", names, shallow=False)
    assert mismatch == [] and errors == [], (mismatch, errors)
    assert match == names


def test_fields_are_copies_in_id_order_and_match_the_frames(tmp_path):
    sim = python_run(cellsph.Scene.load("dam-break-2d"), tmp_path, 3)
    assert sim.steps > 0 and sim.time >= 0.02 * (1 - 1e-12) and sim.dt > 0
    assert sim.wall_corrections == 0  # its walls hold the column by themselves
    n = sim.size
    assert sim.positions.shape == (n, 2) and sim.positions.dtype == np.float64
    assert sim.velocities.shape == (n, 2)
    assert sim.density.shape == (n,) and sim.pressure.shape == (n,)
    assert sim.phase.dtype == np.int32 and sim.kind.dtype == np.uint8
    assert np.array_equal(sim.id, np.arange(n))
    assert int((sim.kind == 0).sum()) == sim.fluid_count
    x = sim.positions
    x[:] = 0  # a copy: the simulation is untouched
    assert np.any(sim.positions != 0)
    all_fields = sim.fields()
    assert list(all_fields) == ["position", "velocity", "force", "mass", "density", "pressure", "support",
                                "color", "viscosity", "phase", "level", "tick", "kind", "id"]
    # The last CSV frame holds the fluid rows of this state, in id order.
    times, frames = zip(*cellsph.read_frames(tmp_path))
    assert len(frames) == 3 and times[-1] == sim.time
    fluid = sim.kind == 0
    for name in ("position", "velocity", "density", "pressure", "phase", "id"):
        assert np.array_equal(frames[-1][name], all_fields[name][fluid]), name
    assert frames[-1]["phase"].dtype == np.int32


def test_emitted_particles_take_new_ids_in_ascending_order():
    sim = cellsph.Simulation(cellsph.Scene.load("channel-inflow"), threads=1)
    n0 = sim.size
    sim.run_until(0.05)  # about 10 layers emitted, as many removed by the sink
    ids = sim.id
    assert np.all(np.diff(ids.astype(np.int64)) > 0)  # unique, in ascending order (the order of the fields)
    assert ids.max() >= n0 + 50  # new ids above the initial ones
    assert len(ids) == sim.size and int((sim.kind == 0).sum()) == sim.fluid_count


def test_read_frames_of_a_vtu_run(cellsph_binary, tmp_path):
    cli_run(cellsph_binary, tmp_path, "dam-break-3d", 0.01, sets=["/spacing=0.1"], formats="vtu,csv")
    vtu = list(cellsph.read_frames(tmp_path, format="vtu"))
    csv = list(cellsph.read_frames(tmp_path, dtype=np.float32))  # a float run: its text reads back as float32
    assert [t for t, _ in vtu] == [t for t, _ in csv] and len(vtu) == 2
    for (_, v), (_, c) in zip(vtu, csv):
        fluid = v["kind"] == 0
        assert v["position"].dtype == np.float32 and v["position"].shape[1] == 3
        assert c["position"].dtype == np.float32
        assert np.array_equal(v["position"][fluid], c["position"])
        assert np.array_equal(v["density"][fluid], c["density"])
        assert np.array_equal(v["id"][fluid], c["id"]) and v["id"].dtype == np.uint32
    with pytest.raises(ValueError, match="format: 'ply' is not among the frames"):
        next(cellsph.read_frames(tmp_path, format="ply"))
    with pytest.raises(ValueError, match="no frames.csv there"):
        next(cellsph.read_frames(tmp_path / "nothing"))


@pytest.mark.parametrize("scene, sets", [("dam-break-2d", ()), ("two-phase", ("/spacing", 0.02))])
def test_checkpoint_and_resume_continue_bit_for_bit(tmp_path, scene, sets):
    s = cellsph.Scene.load(scene)
    if sets:
        s.set(*sets)
    a = cellsph.Simulation(s, threads=2)
    a.run_until(0.01)
    before = a.fields()
    a.checkpoint(tmp_path / "state.bin")
    b = cellsph.Simulation.resume(tmp_path / "state.bin", threads=1)  # any thread count: same bits
    assert b.time == a.time and b.steps == a.steps and b.scene.name == s.name
    after = b.fields()
    for name in before:
        assert np.array_equal(before[name], after[name]), name
    a.run_until(0.02)
    b.run_until(0.02)
    assert a.steps == b.steps
    for name, value in a.fields().items():
        assert np.array_equal(value, b.fields()[name]), name


def test_run_until_callback_and_step(tmp_path):
    sim = cellsph.Simulation(cellsph.Scene.load("dam-break-2d").set("/spacing", 0.03), threads=1)
    seen = []
    sim.run_until(1.0, callback=lambda s: (seen.append(s.steps), len(seen) < 5)[1])
    assert seen == [1, 2, 3, 4, 5] and sim.steps == 5  # returning False stopped it
    sim.step(3)
    assert sim.steps == 8
    t = sim.time
    sim.run_until(t)  # already there: no step
    assert sim.steps == 8


def test_write_frame_numbering_continues_in_a_folder(tmp_path):
    scene = cellsph.Scene.load("dam-break-2d").set("/spacing", 0.03)
    sim = cellsph.Simulation(scene, threads=1)
    files = sim.write_frame(tmp_path, "vtu,csv")
    assert [os.path.basename(f) for f in files] == ["frame_00000.vtu", "frame_00000.csv"]
    sim.step()
    sim.write_frame(tmp_path, ["vtu", "csv"])
    other = cellsph.Simulation(scene, threads=1)  # a new object continues the folder's numbering
    assert os.path.basename(other.write_frame(tmp_path, "vtu,csv")[0]) == "frame_00002.vtu"
    assert os.path.exists(tmp_path / "particles.pvd")
    assert [t for t, _ in cellsph.read_frames(tmp_path)] == [0.0, sim.time, 0.0]
    with pytest.raises(ValueError, match="lists formats 'vtu,csv' but this run writes 'csv'"):
        other.write_frame(tmp_path, "csv")
    with pytest.raises(ValueError, match="formats"):
        sim.write_frame(tmp_path / "x", "png")


def test_scene_from_dict_set_and_to_dict():
    d = cellsph.Scene.load("dam-break-2d").to_dict()
    d["spacing"] = 0.03
    s = cellsph.Scene.from_dict(d)
    assert s.dim == 2 and s.precision == "double" and s.name == "dam-break-2d"
    assert s.end_time == 1.5 and s.fps == 30 and s.formats == ["vtu", "csv"]
    assert s.to_dict() == d
    small = s.particle_count
    s.set("/spacing", 0.04)
    assert s.particle_count < small and s.to_dict()["spacing"] == 0.04
    assert "(edited: /spacing=0.04)" in s.source
    assert "dam-break-2d" in repr(s)
    assert "dam-break-2d" in cellsph.scenes()


def cli_error(binary, tmp_path, scene_dict):
    path = tmp_path / "bad.json"
    path.write_text(json.dumps(scene_dict))
    r = subprocess.run([binary, "run", str(path), "--out", str(tmp_path / "o"), "--quiet"],
                       capture_output=True, text=True)
    assert r.returncode == 2
    return r.stderr


@pytest.mark.parametrize(
    "edit",
    [
        lambda d: d.update(spacing=-1),
        lambda d: d.update(spacnig=0.02),
        lambda d: d["phases"][0].update(viscosity="thick"),
        lambda d: d["solver"].update(model="sph2000"),
    ],
)
def test_scene_errors_have_the_messages_of_the_command_line(cellsph_binary, tmp_path, edit):
    d = cellsph.Scene.load("dam-break-2d").to_dict()
    edit(d)
    with pytest.raises(ValueError) as err:
        cellsph.Scene.from_dict(d, source=str(tmp_path / "bad.json"))
    message = str(err.value)
    assert message in cli_error(cellsph_binary, tmp_path, d)
    assert message.startswith(str(tmp_path / "bad.json") + ": /")


def test_scene_and_simulation_argument_errors(tmp_path):
    with pytest.raises(ValueError, match="'nope' is neither a built-in scene"):
        cellsph.Scene.load("nope")
    with pytest.raises(ValueError, match="scene: expected a dict, got \\[1\\]"):
        cellsph.Scene.from_dict([1])
    with pytest.raises(ValueError, match="not expressible as JSON"):
        cellsph.Scene.from_dict({"spacing": float("nan")})
    s = cellsph.Scene.load("dam-break-2d")
    with pytest.raises(ValueError, match="pointer: 'spacing' is not a JSON pointer"):
        s.set("spacing", 1)
    with pytest.raises(ValueError, match="/spacing"):
        s.set("/spacing", -0.5)
    assert s.to_dict()["spacing"] == 0.02 and "edited" not in s.source  # unchanged after the error
    # No GPU here (nor in CI): a build without CUDA says so, a CUDA build names the runtime's reason.
    with pytest.raises(RuntimeError, match="no CUDA backend|no usable CUDA device"):
        cellsph.Simulation(s, backend="cuda")
    with pytest.raises(ValueError, match="backend: unknown backend 'tpu'"):
        cellsph.Simulation(s, backend="tpu")
    with pytest.raises(ValueError, match="threads: must be >= 1, or 0 for all cores; got -1"):
        cellsph.Simulation(s, threads=-1)
    sim = cellsph.Simulation(s.set("/spacing", 0.03), threads=1)
    with pytest.raises(ValueError, match="count: must be >= 0"):
        sim.step(-1)
    with pytest.raises(ValueError, match="t: must be a finite time"):
        sim.run_until(float("inf"))
    bad = tmp_path / "bad.bin"
    bad.write_bytes(b"not a checkpoint at all")
    with pytest.raises(ValueError, match="bad.bin"):
        cellsph.Simulation.resume(bad)
    with pytest.raises(ValueError, match="missing.bin"):
        cellsph.Simulation.resume(tmp_path / "missing.bin")


def test_a_cellsph_run_checkpoint_is_refused_with_a_hint(cellsph_binary, tmp_path):
    subprocess.run([cellsph_binary, "run", "dam-break-2d", "--set", "/spacing=0.03", "--steps", "2",
                    "--out", str(tmp_path), "--quiet", "--format", "csv"], check=True)
    with pytest.raises(ValueError, match="not written by cellsph.Simulation.checkpoint.*cellsph run --resume"):
        cellsph.Simulation.resume(tmp_path / "checkpoint.bin")


def test_simulation_error_is_a_runtime_error():
    assert issubclass(cellsph.SimulationError, RuntimeError)


def test_host_device_backend_gives_the_cpu_bits():
    # "host-device": the CUDA backend's code path (device arrays, copies, the sorted grid) on the CPU.
    s = cellsph.Scene.load("dam-break-2d").set("/solver/support", 0.1).set("/spacing", 0.05)
    cpu = cellsph.Simulation(s, threads=1)
    dev = cellsph.Simulation(s, threads=1, backend="host-device")
    cpu.step(5)
    dev.step(5)
    assert cpu.time == dev.time
    for name in ("positions", "velocities", "density", "pressure"):
        a, b = getattr(cpu, name), getattr(dev, name)
        assert a.tobytes() == b.tobytes(), name


def test_solver_stats_of_the_implicit_solves():
    # One sweep each and bounds no sweep meets: every solve stops at max_iterations, but step 1's divergence
    # solve, whose fluid starts at rest (error 0).
    scene = cellsph.Scene.load("dam-break-2d-dfsph")
    for pointer, value in [("min_iterations", 1), ("max_iterations", 1), ("max_density_error", 1e-9),
                           ("max_divergence_error", 1e-9)]:
        scene.set("/solver/dfsph/" + pointer, value)
    sim = cellsph.Simulation(scene, threads=1)
    st = sim.solver_stats
    assert st["steps"] == 0 and st["max_iteration_hits"] == 0 and st["last_max_iteration_hit"] is None
    sim.step(8)
    st = sim.solver_stats
    assert st["steps"] == 8
    assert st["density_iterations"] == 8 and st["divergence_iterations"] == 8
    assert st["last_density_iterations"] == 1 and st["last_divergence_iterations"] == 1
    assert st["max_iteration_hits"] == 15
    assert 0 < st["last_density_error_percent"] <= st["max_density_error_percent"]
    hit = st["last_max_iteration_hit"]
    assert hit["step"] == 8 and hit["solve"] == "DFSPH constant-density" and hit["iterations"] == 1
    assert hit["error_percent"] == st["last_density_error_percent"] and hit["bound_percent"] == 1e-9
    # The built-in scene's own bounds: the totals are the sums of the steps', and the solves counted at
    # max_iterations are those that ended above their bound after max_iterations sweeps.
    sim = cellsph.Simulation(cellsph.Scene.load("dam-break-2d-dfsph"), threads=1)
    steps = []
    for _ in range(5):
        sim.step()
        st = sim.solver_stats
        steps.append((st["last_density_iterations"], st["last_density_error_percent"],
                      st["last_divergence_iterations"], st["last_divergence_error_percent"]))
    assert st["density_iterations"] == sum(s[0] for s in steps) >= 2 * 5  # min_iterations 2
    assert st["divergence_iterations"] == sum(s[2] for s in steps)
    assert st["max_density_error_percent"] == max(s[1] for s in steps)
    stopped = [k + 1 for k, s in enumerate(steps) for its, err, bound in ((s[0], s[1], 0.05), (s[2], s[3], 0.1))
               if err > bound]
    assert all(steps[k - 1][0] == 100 or steps[k - 1][2] == 100 for k in stopped)
    assert st["max_iteration_hits"] == len(stopped)
    if stopped:
        assert st["last_max_iteration_hit"]["step"] == stopped[-1]
    assert cellsph.Simulation(cellsph.Scene.load("dam-break-2d").set("/spacing", 0.03), threads=1).solver_stats \
        is None
