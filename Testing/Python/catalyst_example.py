"""Examples/catalyst end to end: the simulation runs ParaView Catalyst in situ on RANKS
ranks (pvbatch, under mpiexec from two), its slabs without ghost layers, and the pipeline
writes its extracts; no error may be logged; then Examples/catalyst/posthoc.py compares
every extract with the same filters run afterwards in one process.
Usage: python3 catalyst_example.py RANKS OUTPUT_FOLDER PLUGIN SITE_PACKAGES WITH_XVFB..."""
import os
import shutil
import subprocess
import sys

ranks, output, plugin, site_packages = int(sys.argv[1]), sys.argv[2], sys.argv[3], sys.argv[4]
display = sys.argv[5:]  # the command that gives the run an X display (pictures)
example = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "Examples", "catalyst")
shutil.rmtree(output, ignore_errors=True)
launch = ["pvbatch"] if ranks == 1 else ["mpiexec", "--allow-run-as-root", "--oversubscribe", "-np", str(ranks),
                                         "pvbatch", "--symmetric"]
environment = dict(os.environ, VAO_PLUGIN=plugin, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")
run = subprocess.run(display + launch + [os.path.join(example, "simulation.py"), "--output", output, "--steps", "3"],
                     capture_output=True, text=True, env=environment)
log = run.stdout + run.stderr
errors = [line for line in log.splitlines() if "ERR|" in line or "Traceback" in line]
print(("ok: " if run.returncode == 0 else "FAILED: ") + "the simulation on %d ranks ran (exit %d)"
      % (ranks, run.returncode))
print(("ok: " if not errors else "FAILED: ") + "no error logged (%s)" % (errors[:3] if errors else "none"))
if run.returncode != 0 or errors:
    print(log[-3000:])
sys.stdout.flush()
posthoc = subprocess.run([sys.executable, os.path.join(example, "posthoc.py"), output, site_packages])
sys.exit(posthoc.returncode or (1 if run.returncode or errors else 0))
