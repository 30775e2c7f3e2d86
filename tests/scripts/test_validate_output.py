#!/usr/bin/python3
"""scripts/validate_output.py: every schema is a valid JSON Schema; a folder that matches passes;
a missing key, a wrong type, a missing file, a file that is not JSON and a usage error fail."""
import json
import pathlib
import subprocess
import sys
import tempfile

import jsonschema

root = pathlib.Path(sys.argv[1])
checker = root / "scripts" / "validate_output.py"
failures = []


def expect(cond, what):
    if not cond:
        failures.append(what)


def check(command, folder):
    p = subprocess.run(["/usr/bin/python3", str(checker), command, str(folder)],
                       capture_output=True, text=True)
    return p.returncode, p.stdout + p.stderr


for schema in sorted((root / "docs" / "schemas").glob("*.schema.json")):
    try:
        jsonschema.Draft202012Validator.check_schema(json.loads(schema.read_text()))
    except jsonschema.SchemaError as e:
        failures.append(f"{schema.name}: not a valid schema: {e.message}")

observer = {"case": "c", "consistency": {"probability": 0.999, "sustain_s": 900.0, "window_s": 1800.0},
            "model": {"kind": "reduced", "order": 84, "rom": "rom"},
            "noise": {"air_walk_K_per_sqrt_h": 0.5, "drift_relative_sigma": 0.04,
                      "drift_sigma_scale": [1.0, 1.0, 1.0],
                      "heat_walk_W_per_sqrt_h": 4.0, "sensor_sigma_K": [0.04]},
            "recalibrate_raised_s": None, "recalibrate_since_s": None, "run": "r",
            "sensors": ["T02"], "status": "ok",
            "unknown_inputs": {"air": {"final_K": 0.1, "sigma_K": 0.2}}}
with tempfile.TemporaryDirectory() as tmp:
    d = pathlib.Path(tmp)
    (d / "observer.json").write_text(json.dumps(observer))
    code, out = check("observe", d)
    expect(code == 0, f"a matching observer.json fails: {out}")

    # A sensor found faulty: the status and the list (absent in files written before it).
    faulty = dict(observer, status="sensor_fault",
                  sensor_faults=[{"sensor": "T02", "offset_K": 0.6, "sigma_K": 0.05,
                                  "since_s": 0.0, "raised_s": 900.0}])
    (d / "observer.json").write_text(json.dumps(faulty))
    code, out = check("observe", d)
    expect(code == 0, f"an observer.json with a sensor fault fails: {out}")
    faulty["sensor_faults"] = [{"sensor": "T02"}]
    (d / "observer.json").write_text(json.dumps(faulty))
    code, out = check("observe", d)
    expect(code == 1 and "'offset_K' is a required property" in out,
           f"a sensor fault without its offset passes: exit {code}: {out}")
    # Where each sensor was read (absent in files written before it): a position or a named point.
    placed = dict(observer, sensor_places=[{"sensor": "T02", "read_at": "position",
                                            "position_m": [0.1, 0.2, 0.3],
                                            "from_named_point_m": 0.0}])
    (d / "observer.json").write_text(json.dumps(placed))
    code, out = check("observe", d)
    expect(code == 0, f"an observer.json with sensor places fails: {out}")
    placed["sensor_places"] = [{"sensor": "T02", "read_at": "nearby"}]
    (d / "observer.json").write_text(json.dumps(placed))
    code, out = check("observe", d)
    expect(code == 1 and "nearby" in out, f"an unknown read_at passes: exit {code}: {out}")
    faulty = dict(observer, status="sensor fault")
    (d / "observer.json").write_text(json.dumps(faulty))
    code, out = check("observe", d)
    expect(code == 1, f"an unknown status passes: exit {code}")

    bad = dict(observer)
    del bad["status"]
    bad["sensors"] = "T02"
    (d / "observer.json").write_text(json.dumps(bad))
    code, out = check("observe", d)
    expect(code == 1, f"a missing key and a wrong type pass: exit {code}")
    expect("'status' is a required property" in out, f"the missing key is not named: {out}")
    expect("sensors" in out and "is not of type 'array'" in out, f"the wrong type is not named: {out}")

    (d / "observer.json").write_text("{ not json")
    code, out = check("observe", d)
    expect(code == 1 and "not JSON" in out, f"a file that is not JSON: exit {code}: {out}")

    code, out = check("fit", d)
    expect(code == 1 and "fit.json: missing" in out, f"a missing file: exit {code}: {out}")

    (d / "observer.json").unlink()
    code, out = check("observe", d)
    expect(code == 1 and "none of observer.json, sigma_calibration.json" in out,
           f"an observe folder with neither file: exit {code}: {out}")

    code, out = check("no-such-command", d)
    expect(code == 2, f"an unknown command: exit {code}")

for f in failures:
    print("FAIL:", f)
print(f"{len(failures)} failure(s)")
sys.exit(1 if failures else 0)
