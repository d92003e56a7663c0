"""Reading ``.npz`` members from an untrusted file: never unpickle, bound what it declares.

``np.load`` allocates whatever a member's header declares before reading a byte of it
(a 3 MB file can declare 3e7 x 720 bytes), and reports damage as KeyError, EOFError,
zlib.error or BadZipFile. :func:`read_member` reads one member's header first, checks the
declared shape against a bound and against the member's declared size, and only then
reads exactly that many bytes; every failure is one :class:`eyeviz.EyevizError` line
naming the file and the member.
"""

from __future__ import annotations

import math
import zipfile
from pathlib import Path

import numpy as np

from eyeviz import EyevizError

__all__ = ["NpzReader", "one_line"]

_MAX_HEADER = 10_000


def one_line(exc: BaseException, limit: int = 200) -> str:
    """The first line of an exception's message (its type name when empty), shortened."""
    text = str(exc).strip().splitlines()
    first = text[0].strip() if text else ""
    if not first or first in ("None", "''"):
        return type(exc).__name__
    return first if len(first) <= limit else first[:limit] + "..."


class NpzReader:
    """An open ``.npz`` whose members are read with :meth:`read_member` only.

    Use as a context manager; ``what`` names the file in messages (default its path)."""

    def __init__(self, path, what: str | None = None) -> None:
        self.path = Path(path)
        self.what = what or str(self.path)
        try:
            self._zf = zipfile.ZipFile(self.path)
            self._infos = {i.filename: i for i in self._zf.infolist()}
        except Exception as exc:  # noqa: BLE001 - any damage is one message
            raise self.fail(f"not a readable .npz ({one_line(exc)})") from None

    def fail(self, msg: str) -> EyevizError:
        return EyevizError(f"{self.what}: {msg}")

    def __enter__(self) -> NpzReader:
        return self

    def __exit__(self, *exc) -> None:
        self._zf.close()

    @property
    def names(self) -> list[str]:
        return [n[:-4] for n in self._infos if n.endswith(".npy")]

    def read_member(
        self,
        name: str,
        max_elements: int,
        dtypes: tuple[str, ...] | None = None,
        ndim: int | None = None,
        max_bytes: int | None = None,
    ) -> np.ndarray:
        """Member ``name`` (without ``.npy``) as an array of at most ``max_elements``
        elements, of one of ``dtypes`` (numpy names such as ``"uint32"``, ``"U"`` for any
        unicode string) and ``ndim`` dimensions when given, in at most ``max_bytes``
        (default 16 bytes per element)."""
        max_bytes = 16 * max_elements if max_bytes is None else max_bytes
        info = self._infos.get(name + ".npy")
        if info is None:
            raise self.fail(f"member {name!r} is missing")
        try:
            with self._zf.open(info) as f:
                version = np.lib.format.read_magic(f)
                if version == (1, 0):
                    shape, fortran, dtype = np.lib.format.read_array_header_1_0(
                        f, max_header_size=_MAX_HEADER
                    )
                elif version in ((2, 0), (3, 0)):
                    shape, fortran, dtype = np.lib.format.read_array_header_2_0(
                        f, max_header_size=_MAX_HEADER
                    )
                else:
                    raise self.fail(f"member {name!r} has .npy version {version}")
                if dtype.hasobject or dtype.fields is not None or dtype.subdtype is not None:
                    raise self.fail(f"member {name!r} has dtype {dtype}, not a plain array")
                if dtypes is not None and not any(
                    dtype.kind == "U" if d == "U" else dtype == np.dtype(d) for d in dtypes
                ):
                    raise self.fail(f"member {name!r} has dtype {dtype}, expected {dtypes}")
                if ndim is not None and len(shape) != ndim:
                    raise self.fail(f"member {name!r} has shape {shape}, expected {ndim}-D")
                count = math.prod(shape)
                if count > max_elements:
                    raise self.fail(
                        f"member {name!r} declares {count} elements, more than {max_elements}"
                    )
                nbytes = count * dtype.itemsize
                if nbytes > max_bytes:
                    raise self.fail(
                        f"member {name!r} declares {nbytes} bytes, more than {max_bytes}"
                    )
                if info.file_size != f.tell() + nbytes:
                    raise self.fail(
                        f"member {name!r} declares shape {shape} ({nbytes} bytes) but holds "
                        f"{info.file_size - f.tell()} bytes"
                    )
                buf = f.read(nbytes)
                if len(buf) != nbytes:
                    raise self.fail(f"member {name!r} ends early")
        except EyevizError:
            raise
        except Exception as exc:  # noqa: BLE001 - zlib.error, BadZipFile, EOFError, ...
            raise self.fail(f"member {name!r} is damaged ({one_line(exc)})") from None
        arr = np.frombuffer(buf, dtype).reshape(shape, order="F" if fortran else "C")
        return arr.copy()
