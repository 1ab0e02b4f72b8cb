"""restitution.sweep.cluster: a LocalCluster's shutdown says nothing after the sweep's own last line."""
import logging

import pytest

pytest.importorskip("distributed", reason="Dask distributed is not installed (the sweep's cluster needs it)")

from restitution.sweep import cluster  # noqa: E402


def _worker_logging_state():
    return logging.root.manager.disable, logging.getLogger("distributed").getEffectiveLevel()


@pytest.mark.slow
def test_closing_a_local_cluster_silences_its_workers_and_restores_this_process():
    """Before the cluster closes, its workers stop logging (a heartbeat that finds the scheduler gone
    printed a traceback after an interrupted sweep's "interrupted" line); this process's Dask logger is
    quiet while the cluster closes and at its old level afterwards."""
    logger = logging.getLogger("distributed")
    before = logger.level
    with cluster._quiet_shutdown() as quiet:
        from distributed import Client, LocalCluster

        with cluster._without_fmu_resources_on_sys_path():  # as open_client starts its workers: with this
            local = LocalCluster(n_workers=1, threads_per_worker=1, processes=True,  # process's restitution
                                 dashboard_address=None, silence_logs=logging.ERROR)
        with local, Client(local) as client:
            assert all(state[0] < logging.CRITICAL for state in client.run(_worker_logging_state).values())
            quiet(client)
            states = client.run(_worker_logging_state)
            assert states and all(state[0] >= logging.CRITICAL for state in states.values()), states
            assert logger.level == logging.CRITICAL
    assert logger.level == before


def test_open_client_quiets_the_cluster_it_started_on_the_way_out(monkeypatch):
    """open_client calls the quiet step for a cluster it started, also when the sweep is interrupted."""
    calls = []
    real = cluster._quiet_shutdown

    def spy():
        manager = real()
        quiet = manager.__enter__()

        class Wrapped:
            def __enter__(self):
                return lambda client: (calls.append(client), quiet(client))

            def __exit__(self, *exc):
                return manager.__exit__(*exc)
        return Wrapped()

    monkeypatch.setattr(cluster, "_quiet_shutdown", spy)
    with pytest.raises(KeyboardInterrupt):
        with cluster.open_client("local", n_workers=1):
            raise KeyboardInterrupt
    assert len(calls) == 1
