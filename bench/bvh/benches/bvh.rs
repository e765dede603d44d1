//! Which BVH crate the tracer uses: obvhs (compressed wide BVH8, SIMD node tests; through our
//! `Accel`) against `bvh` (binary SAH BVH, via its traversal iterator), on the built-in room
//! with incoherent closest-hit rays, the path tracer's workload; and their build times.
//!
//! cargo bench --manifest-path bench/bvh/Cargo.toml

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use glam::Vec3;
use nalgebra::{Point3, Vector3};
use nprt_trace::Accel;

struct Tri {
    p: [Point3<f32>; 3],
    node: usize,
}

impl bvh::aabb::Bounded<f32, 3> for Tri {
    fn aabb(&self) -> bvh::aabb::Aabb<f32, 3> {
        bvh::aabb::Aabb::empty()
            .grow(&self.p[0])
            .grow(&self.p[1])
            .grow(&self.p[2])
    }
}

impl bvh::bounding_hierarchy::BHShape<f32, 3> for Tri {
    fn set_bh_node_index(&mut self, i: usize) {
        self.node = i;
    }
    fn bh_node_index(&self) -> usize {
        self.node
    }
}

/// Deterministic incoherent rays from inside the room.
fn rays(n: usize) -> Vec<(Vec3, Vec3)> {
    let mut state = 0x2545_f491_4f6c_dd1du64;
    let mut next = || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state >> 40) as f32 / (1u64 << 24) as f32
    };
    (0..n)
        .map(|_| {
            let o = Vec3::new(next() * 5.0 - 2.5, next() * 2.6 + 0.2, next() * 5.0 - 2.5);
            let z = next() * 2.0 - 1.0;
            let phi = next() * std::f32::consts::TAU;
            let r = (1.0 - z * z).sqrt();
            (o, Vec3::new(r * phi.cos(), z, r * phi.sin()))
        })
        .collect()
}

fn bench(c: &mut Criterion) {
    let scene = nprt_scene::builtin::scene("room").unwrap();
    let rays = rays(20_000);
    let tris: Vec<[Vec3; 3]> = scene
        .meshes
        .iter()
        .flat_map(|m| m.indices.iter().map(|t| t.map(|i| m.positions[i as usize])))
        .collect();
    let point = |v: Vec3| Point3::new(v.x, v.y, v.z);
    let bvh_shapes = || -> Vec<Tri> {
        tris.iter()
            .map(|t| Tri {
                p: t.map(point),
                node: 0,
            })
            .collect()
    };

    let mut g = c.benchmark_group("build");
    g.sample_size(10);
    g.bench_function("obvhs", |b| b.iter(|| Accel::new(&scene)));
    g.bench_function("bvh", |b| {
        b.iter(|| {
            let mut shapes = bvh_shapes();
            bvh::bvh::Bvh::build(&mut shapes)
        })
    });
    g.finish();

    let accel = Accel::new(&scene);
    let mut shapes = bvh_shapes();
    let tree = bvh::bvh::Bvh::build(&mut shapes);
    let mut g = c.benchmark_group("closest_hit");
    g.throughput(Throughput::Elements(rays.len() as u64));
    g.bench_function("obvhs", |b| {
        b.iter(|| {
            rays.iter()
                .filter_map(|(o, d)| accel.intersect(*o, *d, f32::INFINITY))
                .map(|h| h.t)
                .sum::<f32>()
        })
    });
    g.bench_function("bvh", |b| {
        b.iter(|| {
            let mut total = 0.0;
            for (o, d) in &rays {
                let ray = bvh::ray::Ray::new(point(*o), Vector3::new(d.x, d.y, d.z));
                let best = tree
                    .traverse_iterator(&ray, &shapes)
                    .map(|s| ray.intersects_triangle(&s.p[0], &s.p[1], &s.p[2]).distance)
                    .fold(f32::INFINITY, f32::min);
                if best.is_finite() {
                    total += best;
                }
            }
            total
        })
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
