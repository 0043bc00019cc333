"""A ``--scheduler`` address: checked, then probed before Dask is given it (docs/fleet.md).

Dask's client trusts what answers at the address: a service that sends other bytes first
has its first 8 bytes read as a message length (an allocation of exabytes, a MemoryError),
a silent one can hold the client past its connect timeout, and a malformed address raises
whatever the URL parser raises. So, before :class:`distributed.Client` is made:

1. :func:`parse_address` checks the text: ``[SCHEME://]HOST:PORT`` with a scheme Dask
   speaks (:data:`SCHEMES`, ``tcp`` when left out), a host and a port 1–65535;
2. :func:`probe` (plain ``tcp`` only; TLS and the others are left to Dask with its timeout)
   connects and reads the scheduler's greeting within :data:`PROBE_TIMEOUT_S`: a Dask comm
   opens with an 8-byte little-endian length and then that many bytes of handshake — a
   length outside 1 byte–:data:`MAX_GREETING_BYTES`, or nothing in time, is not a Dask
   scheduler.

Every failure is one :class:`~drillfric.errors.InputError` naming the address.
"""

from __future__ import annotations

import socket
import struct
import time
from urllib.parse import urlsplit

from drillfric.errors import InputError

#: Address schemes of Dask's comms.
SCHEMES = ("tcp", "tls", "ucx", "ws", "wss", "inproc")
#: Seconds to connect and read a scheduler's greeting.
PROBE_TIMEOUT_S = 5.0
#: Largest plausible handshake of a Dask scheduler [bytes] (it is ~100 bytes).
MAX_GREETING_BYTES = 1 << 20
_FIX = "give the address the scheduler prints (tcp://HOST:8786) and check that it runs"


def parse_address(text: str) -> tuple[str, str, int]:
    """``(scheme, host, port)`` of a scheduler address.

    Examples
    --------
    >>> parse_address("tcp://10.0.0.5:8786"), parse_address("[::1]:8786")
    (('tcp', '10.0.0.5', 8786), ('tcp', '::1', 8786))

    Raises
    ------
    InputError
        Unknown scheme, no host, no port or a port out of range, or not a URL at all.
    """
    where = shown(text)
    full = text if "://" in text else f"tcp://{text}"
    try:
        parts = urlsplit(full)
        port = parts.port
    except ValueError as exc:
        raise InputError(f"not a scheduler address ({exc})", file=where, fix=_FIX) from None
    scheme = parts.scheme.lower()
    if scheme not in SCHEMES:
        raise InputError(f"not a Dask scheduler address (scheme '{scheme}'; Dask speaks "
                         f"{', '.join(SCHEMES)})", file=where, fix=_FIX)
    if not parts.hostname or port is None or parts.path not in ("", "/") or parts.query:
        raise InputError("not a scheduler address (it needs a host and a port, nothing "
                         "else)", file=where, fix=_FIX)
    if not 0 < port < 65536:
        raise InputError(f"port {port} out of range", file=where, fix=_FIX)
    return scheme, parts.hostname, port


def probe(text: str, timeout_s: float = PROBE_TIMEOUT_S) -> None:
    """Check that a ``tcp`` address answers like a Dask scheduler (others: nothing checked).

    Raises
    ------
    InputError
        Cannot connect, silent, closed at once, or its first bytes are not a Dask greeting.
    """
    scheme, host, port = parse_address(text)
    if scheme != "tcp":
        return
    deadline = time.monotonic() + timeout_s
    try:
        with socket.create_connection((host, port), timeout=timeout_s) as sock:
            size = struct.unpack("<Q", _read(sock, 8, deadline))[0]
            if not 0 < size <= MAX_GREETING_BYTES:
                raise _not_dask(text, "its first bytes are not a Dask message")
            _read(sock, size, deadline)
    except TimeoutError:
        raise _not_dask(text, f"it sent nothing within {timeout_s:g} s") from None
    except ConnectionRefusedError:
        raise InputError("cannot reach the Dask scheduler (connection refused)",
                         file=shown(text), fix=_FIX) from None
    except ConnectionError as exc:
        raise _not_dask(text, f"the connection closed ({exc.strerror or 'no greeting'})"
                        ) from None
    except OSError as exc:
        raise InputError(f"cannot reach the Dask scheduler ({exc.strerror or exc})",
                         file=shown(text), fix=_FIX) from None


def _read(sock: socket.socket, size: int, deadline: float) -> bytes:
    data = bytearray()
    while len(data) < size:
        sock.settimeout(max(deadline - time.monotonic(), 0.001))
        chunk = sock.recv(min(size - len(data), 65536))
        if not chunk:
            raise ConnectionResetError(0, "closed before its greeting")
        data += chunk
    return bytes(data)


def _not_dask(text: str, why: str) -> InputError:
    return InputError(f"the address does not answer as a Dask scheduler ({why})",
                      file=shown(text), fix=_FIX)


def shown(text: str) -> str:
    """The address as printed: control characters escaped, at most 200 characters."""
    return repr(str(text))[1:-1][:200]
