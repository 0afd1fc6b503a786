"""The array types every module annotates with, defined once.

Times are int64 nanoseconds (:data:`I64`), lengths and angles float64 (:data:`F64`), raw bag
bytes uint8 (:data:`U8`).
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

F64 = npt.NDArray[np.float64]
I64 = npt.NDArray[np.int64]
I32 = npt.NDArray[np.int32]
U8 = npt.NDArray[np.uint8]
Bool = npt.NDArray[np.bool_]
IntArr = npt.NDArray[np.intp]
