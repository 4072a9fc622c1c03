"""Building blocks of the algorithms' gradient updates, beside the networks of :mod:`pamdp.policies`.

- ``dense.py``: hand-written forward and backward passes of :func:`~pamdp.policies.mlp` networks (``Dense``, and
  MP-DQN's ``MultiPassDense``), autograd's gradients in fewer calls.
- ``optim.py``: the one optimizer step of every update (``descend``, ``apply_gradients``).
- ``subnormals.py``: subnormal floats flushed to zero in the updates (the ``flush_denormal`` setting).

They know no algorithm and no env: the algorithms (:mod:`pamdp.algos`) import them.
"""
