"""keep_freed_memory(): after it, a 48 MiB block (above the largest mmap
threshold glibc accepts) comes from the heap and its free leaves the heap at
its size; without it glibc maps such a block on its own. Each case runs in a
fresh interpreter (the setting is process-wide)."""

import ctypes.util
import os
import subprocess
import sys

import pytest

PROBE = r"""
import ctypes, sys
import ceres_sesync as cs

class MallInfo2(ctypes.Structure):
    _fields_ = [(name, ctypes.c_size_t) for name in (
        "arena", "ordblks", "smblks", "hblks", "hblkhd", "usmblks",
        "fsmblks", "uordblks", "fordblks", "keepcost")]

libc = ctypes.CDLL(None)
libc.mallinfo2.restype = MallInfo2
libc.malloc.restype = ctypes.c_void_p
libc.malloc.argtypes = [ctypes.c_size_t]
libc.free.argtypes = [ctypes.c_void_p]
kept = cs.keep_freed_memory() if sys.argv[1] == "keep" else None
size = 48 << 20
mapped_before = libc.mallinfo2().hblkhd
block = libc.malloc(size)
ctypes.memset(block, 1, size)
during = libc.mallinfo2()
libc.free(block)
after = libc.mallinfo2()
print(kept, during.hblkhd - mapped_before, after.arena - during.arena)
"""


def probe(mode):
    result = subprocess.run(
        [sys.executable, "-c", PROBE, mode],
        capture_output=True,
        text=True,
        env=os.environ,
    )
    assert result.returncode == 0, result.stderr
    kept, mapped, heap_change = result.stdout.split()
    return kept, int(mapped), int(heap_change)


def glibc_with_mallinfo2():
    libc = ctypes.CDLL(None)
    return ctypes.util.find_library("c") and hasattr(libc, "mallinfo2")


@pytest.mark.skipif(not glibc_with_mallinfo2(), reason="glibc >= 2.33 only")
def test_keep_freed_memory_keeps_blocks_in_the_heap():
    kept, mapped, heap_change = probe("keep")
    assert kept == "True"
    assert mapped == 0  # Not mapped on its own.
    assert heap_change == 0  # Not trimmed after the free.


@pytest.mark.skipif(not glibc_with_mallinfo2(), reason="glibc >= 2.33 only")
def test_without_it_glibc_maps_the_block():
    kept, mapped, _ = probe("default")
    assert kept == "None"
    assert mapped >= 48 << 20
