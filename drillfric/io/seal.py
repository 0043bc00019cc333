"""A seal on the saved state: a later run continues only from a state this user's drillfric
wrote (docs/security.md, "The saved state").

The state (``OUT/NAME/state/``) and the result files a resumed run carries over
(``estimates.parquet``, ``profiles.parquet``) lie in OUT, where anyone with write access
may change them. Checking every value of a state for plausibility is an open-ended list (a
cursor past the rows read, two buffers of different lengths, a text where a time goes…):
each escaped value becomes an internal error every night, a number blamed on the user's
data, or — worst — a silently wrong result. Instead :func:`seal` writes ``seal.json``: the
SHA-256 of each of those files and an HMAC-SHA256 of that list under a key kept outside
OUT (:func:`key`), and :func:`broken` refuses a state whose files or seal do not match.
Such a state is never an error: the well runs from its start, and summary.json
``resumed.reason`` says why.

The key: ``DRILLFRIC_STATE_KEY`` (text; give every machine of a cluster the same one), else
``$XDG_CONFIG_HOME/drillfric/state.key`` (``~/.config``), 32 random bytes made on first use,
mode 0600. Without a key — a home that cannot be written, or a key file that is not one
(a link, a FIFO, a device, another length, readable by others, another user's: a weak key
would let anyone forge a seal) — nothing is sealed and nothing resumed.
"""

from __future__ import annotations

import hashlib
import hmac
import json
import os
import secrets
import stat
from pathlib import Path

from drillfric.io.atomic import own_file
from drillfric.io.digest import sha256_prefix

SEAL = "seal.json"
KEY_ENV = "DRILLFRIC_STATE_KEY"
#: The result files beside the state that a resumed run carries over.
CARRIED = ("estimates.parquet", "profiles.parquet")


#: Bytes of a key file (what :func:`_make` writes; anything else is not a key).
KEY_BYTES = 32


def key() -> bytes | None:
    """The sealing key (see the module's text), or None when none can be had: no key file
    can be made, or the one there is not a key (a link, a FIFO, a device, not 32 bytes,
    readable by others, another user's) — then nothing is sealed or resumed."""
    given = os.environ.get(KEY_ENV)
    if given:
        return hashlib.sha256(given.encode("utf-8", "surrogateescape")).digest()
    base = Path(os.environ.get("XDG_CONFIG_HOME") or Path.home() / ".config")
    path = base / "drillfric" / "state.key"
    try:
        return _read(path) if os.path.lexists(path) else _make(path)
    except OSError:
        return None


def _read(path: Path) -> bytes | None:
    """The key in ``path``, opened without following a link or blocking on a FIFO, and
    only a regular file of :data:`KEY_BYTES` bytes, mode 0600 or stricter, this user's."""
    fd = os.open(path, os.O_RDONLY | os.O_NOFOLLOW | os.O_NONBLOCK)
    try:
        info = os.fstat(fd)
        if not stat.S_ISREG(info.st_mode) or info.st_size != KEY_BYTES or \
                info.st_mode & 0o077 or info.st_uid != os.geteuid():
            return None
        data = os.read(fd, KEY_BYTES + 1)
    finally:
        os.close(fd)
    return data if len(data) == KEY_BYTES else None


def _make(path: Path) -> bytes | None:
    """A new key at ``path`` (0600; a concurrent maker's key wins: O_EXCL)."""
    path.parent.mkdir(parents=True, exist_ok=True, mode=0o700)
    fresh = secrets.token_bytes(KEY_BYTES)
    try:
        fd = os.open(path, os.O_WRONLY | os.O_CREAT | os.O_EXCL | os.O_NOFOLLOW, 0o600)
    except FileExistsError:
        return _read(path)
    with os.fdopen(fd, "wb") as fh:
        fh.write(fresh)
    return fresh


def _sealed_files(state: Path) -> dict[str, Path]:
    """Name (relative to the result directory) → path of every sealed file that exists."""
    files = {f"state/{p.name}": p for p in sorted(state.iterdir())
             if p.name != SEAL and not p.name.startswith(".")}
    files |= {name: state.parent / name for name in CARRIED if (state.parent / name).exists()}
    return files


def _mac(secret: bytes, digests: dict[str, str]) -> str:
    text = json.dumps(digests, sort_keys=True).encode()
    return hmac.new(secret, text, hashlib.sha256).hexdigest()


def seal(state: Path) -> bool:
    """Write ``state/seal.json`` over the state and the carried result files; False (and no
    seal) without a key."""
    secret = key()
    if secret is None:
        return False
    digests = {name: sha256_prefix(path) for name, path in _sealed_files(state).items()}
    (state / SEAL).write_text(json.dumps({"files": digests, "hmac": _mac(secret, digests)},
                                         sort_keys=True), encoding="utf-8")
    return True


def broken(state: Path) -> str:
    """Why the state in ``state`` may not be continued from ("" when its seal holds)."""
    secret = key()
    if secret is None:
        return f"no key to check the saved state's seal (set {KEY_ENV})"
    try:
        doc = json.loads(own_file(state / SEAL).read_text(encoding="utf-8"))
        digests, mac = doc["files"], doc["hmac"]
        if not (isinstance(digests, dict) and isinstance(mac, str)):
            raise ValueError
    except (OSError, ValueError, KeyError, TypeError, RecursionError):
        return "the saved state has no seal this drillfric can read"
    if not hmac.compare_digest(_mac(secret, digests), mac):
        return "the saved state's seal is not this user's drillfric's (another key, or changed)"
    files = _sealed_files(state)
    if set(files) != set(digests):
        return "the saved state's files are not the ones sealed"
    for name, path in files.items():
        try:
            same = sha256_prefix(own_file(path)) == digests[name]
        except (OSError, ValueError):
            same = False
        if not same:
            return f"{name} changed since the state was sealed"
    return ""
