"""A batch trial through the Python client (README, "Batch scripts: the Python client"): an
experiment, one tagged run per zeta0 of a sweep, an MJTF job over the same levels, a summary.

Start the service (``./run.sh``), then from the repository root::

    .venv/bin/python scripts/batch_trials_example.py

It talks to ``$PARKOUR_URL`` (default http://127.0.0.1:8000) with the token of
``$PARKOUR_API_TOKEN`` or ``./data/api_token``. It imports only ``parkourlab``.
"""

from __future__ import annotations

from parkourlab import Client, ParkourError

PSI0_DEG = 30.0  # leg angle at touchdown [deg]
ZETA0S = [0.86, 0.88, 0.90, 0.92]  # leg length at touchdown [l0]: the energy levels swept
START = (-0.93, -0.17)  # section state (xdot, ydot) [sqrt(g l0)]
TAG = "batch-example"


def main() -> None:
    with Client() as client:
        client.wait_ready(timeout=300)  # [s] a service just started loads its workers first
        experiment = client.create_experiment("zeta0 batch", description="scripts/batch_trials_example.py")
        try:
            for zeta0 in ZETA0S:
                client.create_run(
                    [(PSI0_DEG, zeta0)], START, jumps=20, tags=[TAG, f"zeta0:{zeta0}"], experiment_id=experiment["id"]
                )
            job = client.submit_mjtf(
                ZETA0S, psi0_deg=PSI0_DEG, trials=32, cap=300, seed=1, experiment_id=experiment["id"]
            )
        except ParkourError:  # leave nothing behind: the runs made so far, then the experiment
            for run in client.runs(experiment_id=experiment["id"]):
                client.delete_run(run["id"])
            client.delete_experiment(experiment["id"])
            raise
        client.wait(job, progress=True, timeout=600)  # [s]
        mjtf = {level["zeta0"]: level for level in client.results(job)["levels"]}

        print(f"experiment {experiment['id']}, MJTF job {job['id']}: psi0 = {PSI0_DEG:g} deg")
        print(f"{'zeta0':>6} {'run':>5} {'climb [l0]':>10} {'jumps':>5} {'MJTF':>7} {'± std':>6}")
        for run in client.runs(experiment_id=experiment["id"], tag=TAG, sort="zeta0"):
            zeta0 = run["controls"][0][1]
            level = mjtf[zeta0]
            print(
                f"{zeta0:6.2f} {run['id']:5d} {run['climb']:10.3f} {run['jumps_completed']:5d}"
                f" {level['mean']:7.1f} {level['std']:6.1f}"
            )


if __name__ == "__main__":
    main()
