"""Times `Rig.evaluate` on a file: every bone at its scan times (every key, 60 Hz) into numpy arrays, the best of
several runs, against the criterion bench of the same work in Rust (`cargo bench --bench sample`).

    cargo run --release --locked --example write_generated_gltf -- /tmp/gen
    python python/bench/evaluate.py /tmp/gen/generated_200x6000.glb
"""

import sys
import time

import bonescope

rig = bonescope.load(sys.argv[1])
runs = int(sys.argv[2]) if len(sys.argv) > 2 else 10
taken = []
for _ in range(runs):
    started = time.perf_counter()
    evaluation = rig.evaluate()
    taken.append(time.perf_counter() - started)
    del evaluation
taken.sort()
shape = rig.evaluate().model.shape
print(
    f"Rig.evaluate of {sys.argv[1]}: {shape[0]} times × {shape[1]} bones, {runs} runs: "
    f"median {taken[len(taken) // 2] * 1000:.1f} ms, best {taken[0] * 1000:.1f} ms"
)
