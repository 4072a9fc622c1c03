"""Independent numerical checks shared by the tests (importable: pytest puts ``tests/`` on ``sys.path``)."""

import torch


def finite_difference(f, tensors, h=1e-6):
    """Central differences of the scalar ``f()`` with respect to every entry of ``tensors`` (edited in place)."""
    out = []
    for t in tensors:
        g = torch.zeros_like(t)
        flat, gflat = t.data.view(-1), g.view(-1)
        for i in range(flat.numel()):
            old = flat[i].item()
            flat[i] = old + h
            up = f()
            flat[i] = old - h
            down = f()
            flat[i] = old
            gflat[i] = (up - down) / (2 * h)
        out.append(g)
    return out
