#!/usr/bin/python3
"""Checks a thermotwin output folder against the documented schemas (docs/schemas/).

Usage: validate_output.py COMMAND DIR
  COMMAND: the command that wrote DIR (mesh, run, reduce, place, fit, calibrate, probes, observe,
  export).
Every JSON file that COMMAND always writes must be in DIR and match its schema; a file that it
writes only in some modes (modelling_record.json, sensor_corrections.json) is checked when there.
Exit 0 when all match; 1 with one line per problem (file, JSON path, message) otherwise; 2 on a
usage error. Needs Debian's python3-jsonschema (scripts/setup.sh installs it).
"""
import json
import pathlib
import sys

SCHEMAS = pathlib.Path(__file__).resolve().parent.parent / "docs" / "schemas"

# command -> [(file, schema, always written)]
OUTPUTS = {
    "mesh": [("mesh_report.json", "mesh_report", True)],
    "run": [("mesh_report.json", "mesh_report", True), ("summary.json", "run_summary", True)],
    "reduce": [("reduced_model.json", "reduced_model", True)],
    "place": [("placement.json", "placement", True)],
    "fit": [("fit.json", "fit", True), ("modelling_record.json", "modelling_record", False)],
    "calibrate": [("calibration.json", "calibration", True),
                  ("sensor_corrections.json", "sensor_corrections", False)],
    "probes": [("summary.json", "probes_summary", True)],
    "observe": [("observer.json", "observer", False),
                ("sigma_calibration.json", "sigma_calibration", False)],
    "export": [("export.json", "export", True)],
}

# command -> files of which it writes at least one (observe: the run observed, the sigma
# calibrated on training runs, or both)
ONE_OF = {"observe": ["observer.json", "sigma_calibration.json"]}


def problems(command, folder):
    try:
        import jsonschema
    except ImportError:
        return ["python3-jsonschema is not installed (apt-get install python3-jsonschema)"]
    found = []
    if command in ONE_OF and not any((folder / n).exists() for n in ONE_OF[command]):
        found.append(f"{folder}: none of {', '.join(ONE_OF[command])} ({command} writes one)")
    for name, schema_name, always in OUTPUTS[command]:
        path = folder / name
        if not path.exists():
            if always:
                found.append(f"{path}: missing ({command} always writes it)")
            continue
        schema = json.loads((SCHEMAS / f"{schema_name}.schema.json").read_text())
        try:
            document = json.loads(path.read_text())
        except ValueError as e:
            found.append(f"{path}: not JSON: {e}")
            continue
        validator = jsonschema.Draft202012Validator(schema)
        for error in sorted(validator.iter_errors(document), key=lambda e: list(e.path)):
            where = "/".join(str(p) for p in error.absolute_path) or "(top level)"
            found.append(f"{path}: {where}: {error.message[:300]}")
    return found


def main(argv):
    if len(argv) != 3 or argv[1] not in OUTPUTS:
        sys.stderr.write(__doc__)
        return 2
    folder = pathlib.Path(argv[2])
    if not folder.is_dir():
        sys.stderr.write(f"validate_output.py: {folder}: not a folder\n")
        return 2
    found = problems(argv[1], folder)
    for p in found:
        print(p)
    return 1 if found else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
