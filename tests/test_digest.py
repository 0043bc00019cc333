"""drillfric.io.digest: the SHA-256 of a file's first bytes, each byte read once per process
(a grown well's nightly re-run hashed the same file four times: docs/performance.md)."""

from __future__ import annotations

import hashlib
import os

import pytest

from drillfric.io import digest


@pytest.fixture
def small_steps(monkeypatch):
    """Kept states every 64 bytes, read 16 at a time (a test file of a few KB spans many)."""
    monkeypatch.setattr(digest, "STEP", 64)
    monkeypatch.setattr(digest, "BLOCK", 16)
    monkeypatch.setattr(digest, "_kept", type(digest._kept)())


def test_every_prefix_equals_hashlib_in_any_order(tmp_path, small_steps):
    data = os.urandom(1000)
    path = tmp_path / "log.csv"
    path.write_bytes(data)
    sizes = [1000, 0, 63, 64, 65, 999, 128, 500, 1, 1000]  # whole first, then prefixes
    for n in sizes:
        assert digest.sha256_prefix(path, n) == hashlib.sha256(data[:n]).hexdigest()
    assert digest.sha256_prefix(path) == hashlib.sha256(data).hexdigest()


def test_a_file_grown_or_rewritten_is_hashed_afresh(tmp_path, small_steps):
    path = tmp_path / "log.csv"
    path.write_bytes(b"a" * 300)
    digest.sha256_prefix(path)
    path.write_bytes(b"b" * 300)  # same size, new content (and modification time)
    os.utime(path, ns=(0, 10**9))
    assert digest.sha256_prefix(path, 200) == hashlib.sha256(b"b" * 200).hexdigest()
    with open(path, "ab") as fh:
        fh.write(b"c" * 50)
    assert digest.sha256_prefix(path) == hashlib.sha256(b"b" * 300 + b"c" * 50).hexdigest()


def test_a_prefix_longer_than_the_file_is_refused(tmp_path):
    path = tmp_path / "log.csv"
    path.write_bytes(b"abc")
    with pytest.raises(ValueError):
        digest.sha256_prefix(path, 4)
