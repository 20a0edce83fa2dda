"""fmutrace's optional C code: each extension module (_steps.c, the step
loop; _rows.c, the reader of plain CSV rows) is a plain library to cffi,
found beside the package, not imported. Where one was not built (no C
compiler at install), its caller does the same work in Python or pyarrow."""

import importlib.util

import cffi


def native_function(module: str, ffi: cffi.FFI, name: str):
    """The function name of the extension module (declared in ffi's cdef);
    None if the module was not built."""
    spec = importlib.util.find_spec(f"{__package__}.{module}")
    if spec is None or spec.origin is None:
        return None
    try:
        return getattr(ffi.dlopen(spec.origin), name)
    except (OSError, AttributeError):
        return None
