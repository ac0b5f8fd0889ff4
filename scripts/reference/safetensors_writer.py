"""A safetensors file from a dict of float32 torch tensors or NumPy arrays (the format: an 8-byte
little-endian header length, a JSON header of dtypes, shapes and offsets, then the raw data), so
that the reference scripts need nothing beyond torch or NumPy."""

import json
import struct


def write(path, tensors):
    header, blobs, offset = {}, [], 0
    for name in sorted(tensors):
        t = tensors[name]
        if hasattr(t, "detach"):  # a torch tensor
            t = t.detach().to("cpu").float().contiguous().numpy()
        import numpy  # a torch script has it too

        t = numpy.ascontiguousarray(t, dtype="<f4")
        data = t.tobytes()
        header[name] = {
            "dtype": "F32",
            "shape": list(t.shape),
            "data_offsets": [offset, offset + len(data)],
        }
        blobs.append(data)
        offset += len(data)
    text = json.dumps(header, separators=(",", ":")).encode()
    text += b" " * (-len(text) % 8)
    path.parent.mkdir(parents=True, exist_ok=True)
    with open(path, "wb") as f:
        f.write(struct.pack("<Q", len(text)))
        f.write(text)
        for blob in blobs:
            f.write(blob)
