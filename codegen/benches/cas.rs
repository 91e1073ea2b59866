//! Scale of the symbolic core: building, differentiating and scheduling a graph of about a
//! million nodes (the size a 48-joint robot's derivation reaches).
//!
//! `cargo bench -p eomgen --bench cas`; criterion reports elements (nodes) per second.

use criterion::{criterion_group, criterion_main, BatchSize, Criterion, Throughput};
use eomgen::cas::{Graph, Id, Program};

const JOINTS: usize = 48;
const STEPS: usize = 1_000_000;

/// A deterministic pseudo-random graph shaped like dynamics: sums and products of earlier
/// subexpressions (favouring recent ones, as recursions do), sin/cos of joint angles, constants.
fn build() -> (Graph, Vec<Id>) {
    let mut g = Graph::new();
    let mut pool: Vec<Id> = Vec::with_capacity(STEPS);
    for i in 0..JOINTS {
        let q = g.q(i);
        pool.push(q);
        pool.push(g.sin(q));
        pool.push(g.cos(q));
    }
    let mut state = 0x2545_f491_4f6c_dd1du64;
    let mut next = || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        state
    };
    for _ in 0..STEPS {
        let r = next();
        let len = pool.len() as u64;
        // Mostly recent operands, sometimes any.
        let pick = |x: u64| -> usize {
            (if x % 4 == 0 {
                x % len
            } else {
                len - 1 - (x >> 8) % len.min(64)
            }) as usize
        };
        let (a, b) = (pool[pick(r >> 3)], pool[pick(r >> 23)]);
        let e = match r % 8 {
            0..=2 => {
                let k = ((r >> 40) % 7) as f64 - 3.0;
                g.sum(0.0, [(a, 1.0), (b, if k == 0.0 { 0.5 } else { k })])
            }
            3..=5 => g.mul(a, b),
            6 => {
                let c = g.constant(((r >> 44) % 1000) as f64 / 997.0);
                g.mul(a, c)
            }
            _ => g.sub(a, b),
        };
        pool.push(e);
    }
    let outputs = pool[pool.len() - 1000..].to_vec();
    (g, outputs)
}

fn bench(c: &mut Criterion) {
    let (graph, outputs) = build();
    let nodes = graph.len() as u64;
    println!("graph: {} nodes", nodes);
    let mut group = c.benchmark_group("cas");
    group.sample_size(10);
    group.throughput(Throughput::Elements(nodes));
    group.bench_function("build", |b| b.iter(build));
    group.bench_function("differentiate", |b| {
        b.iter_batched(
            || graph.clone(),
            |mut g| {
                let q = g.q(0);
                g.diff_many(&outputs, q)
            },
            BatchSize::LargeInput,
        )
    });
    group.bench_function("schedule", |b| b.iter(|| Program::new(&graph, &outputs)));
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
