"""The fmutrace tier: a test that starts a Dask cluster says so with the
marker cluster, which the fast lane leaves out (docs/testing.md)."""

import pytest


@pytest.fixture(autouse=True)
def clusters_only_where_marked(request, monkeypatch):
    """A campaign of an unmarked test that would run on Dask (a local
    cluster, or a scheduler's) fails, naming the marker it lacks: the fast
    lane stays free of clusters as tests are added."""
    if request.node.get_closest_marker("cluster"):
        return
    from fmutrace import _executors as executors

    def refuse(self, *args, **kwargs):
        raise AssertionError(f"{request.node.nodeid} runs a campaign on Dask: mark it @pytest.mark.cluster")

    monkeypatch.setattr(executors.Dask, "run", refuse)
