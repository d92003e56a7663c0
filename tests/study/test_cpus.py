"""Local workers are sized to the CPUs this process may use: affinity and the cgroup
quota (v2 cpu.max, v1 cfs quota), read from a fake file system root (issue 25)."""

import os

import pytest

from eyeviz.study.cpus import cgroup_quota, usable_cpus


def _write(root, rel, text):
    p = root / rel
    p.parent.mkdir(parents=True, exist_ok=True)
    p.write_text(text)


def test_cgroup_v2_quota_caps_the_workers(tmp_path):
    _write(tmp_path, "proc/self/cgroup", "0::/box/job\n")
    _write(tmp_path, "sys/fs/cgroup/box/cpu.max", "max 100000\n")
    _write(tmp_path, "sys/fs/cgroup/box/job/cpu.max", "150000 100000\n")
    assert cgroup_quota(tmp_path) == pytest.approx(1.5)
    assert usable_cpus(tmp_path) == min(2, len(os.sched_getaffinity(0)))


def test_a_parent_cgroups_quota_counts(tmp_path):
    _write(tmp_path, "proc/self/cgroup", "0::/box/job\n")
    _write(tmp_path, "sys/fs/cgroup/box/cpu.max", "100000 100000\n")
    _write(tmp_path, "sys/fs/cgroup/box/job/cpu.max", "max 100000\n")
    assert cgroup_quota(tmp_path) == pytest.approx(1.0)
    assert usable_cpus(tmp_path) == 1


def test_cgroup_v1_quota(tmp_path):
    _write(tmp_path, "proc/self/cgroup", "4:memory:/x\n1:cpu,cpuacct:/x\n")
    _write(tmp_path, "sys/fs/cgroup/cpu/x/cpu.cfs_quota_us", "50000\n")
    _write(tmp_path, "sys/fs/cgroup/cpu/x/cpu.cfs_period_us", "100000\n")
    assert cgroup_quota(tmp_path) == pytest.approx(0.5)
    assert usable_cpus(tmp_path) == 1


def test_no_quota_is_the_affinity(tmp_path):
    _write(tmp_path, "proc/self/cgroup", "0::/\n")
    _write(tmp_path, "sys/fs/cgroup/cpu.max", "max 100000\n")
    assert cgroup_quota(tmp_path) is None
    assert usable_cpus(tmp_path) == len(os.sched_getaffinity(0))
    assert cgroup_quota(tmp_path / "nowhere") is None


def test_the_runner_sizes_its_local_cluster_by_usable_cpus(monkeypatch):
    from eyeviz.study import runner

    monkeypatch.setattr(runner, "usable_cpus", lambda: 3)
    assert runner._cores() == 3
