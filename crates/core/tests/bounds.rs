//! Boxes and bounding spheres against values worked out by hand: every measure, every
//! branch of the slab test and the sphere union, and the ends of every interval.

use raylab_core::{Aabb, BoundingSphere, Ray, Vec3};

fn v(x: f32, y: f32, z: f32) -> Vec3 {
    Vec3::new(x, y, z)
}

#[test]
fn boxes_from_points_union_and_intersection() {
    assert_eq!(Aabb::default(), Aabb::EMPTY);
    let b = Aabb::from_points([v(1.0, 2.0, 3.0), v(-1.0, 5.0, 0.0), v(0.0, 0.0, 4.0)]);
    assert_eq!((b.min, b.max), (v(-1.0, 0.0, 0.0), v(1.0, 5.0, 4.0)));
    assert_eq!(Aabb::from_points([]), Aabb::EMPTY);
    assert_eq!(Aabb::EMPTY.grow(v(1.0, 2.0, 3.0)), Aabb::new(v(1.0, 2.0, 3.0), v(1.0, 2.0, 3.0)));

    let a = Aabb::new(Vec3::ZERO, Vec3::ONE);
    let u = a.union(Aabb::new(v(-1.0, 0.5, 2.0), v(0.5, 3.0, 2.5)));
    assert_eq!((u.min, u.max), (v(-1.0, 0.0, 0.0), v(1.0, 3.0, 2.5)));
    assert_eq!(a.union(Aabb::EMPTY), a);

    let i = a.intersection(Aabb::new(v(0.5, -1.0, 0.25), v(2.0, 0.5, 0.75)));
    assert_eq!((i.min, i.max), (v(0.5, 0.0, 0.25), v(1.0, 0.5, 0.75)));
    // Disjoint along z only: empty.
    assert!(a.intersection(Aabb::new(v(-1.0, 0.5, 2.0), v(0.5, 3.0, 2.5))).is_empty());
}

#[test]
fn emptiness_and_the_measures_of_degenerate_boxes() {
    // A point is a box (not empty); one inverted axis is enough to be empty.
    let point = Aabb::new(Vec3::ONE, Vec3::ONE);
    assert!(!point.is_empty());
    assert!(Aabb { min: v(0.0, 1.0, 0.0), max: v(1.0, 0.5, 1.0) }.is_empty());
    assert_eq!((Aabb::EMPTY.extent(), Aabb::EMPTY.volume()), (Vec3::ZERO, 0.0));
    assert_eq!(Aabb::new(Vec3::ZERO, v(2.0, 0.0, 3.0)).volume(), 0.0);
    assert_eq!(Aabb::new(Vec3::ZERO, v(2.0, 3.0, 5.0)).volume(), 30.0);
    // A flat box has the area of its two faces.
    assert_eq!(Aabb::new(Vec3::ZERO, v(2.0, 0.0, 3.0)).surface_area(), 12.0);
    assert_eq!(Aabb::new(Vec3::ZERO, v(2.0, 0.0, 3.0)).half_area(), 6.0);
}

#[test]
fn the_longest_axis_breaks_ties_toward_x_then_y() {
    let axis = |x, y, z| Aabb::new(Vec3::ZERO, v(x, y, z)).max_axis();
    assert_eq!([axis(2.0, 2.0, 1.0), axis(1.0, 2.0, 2.0), axis(2.0, 1.0, 2.0), axis(1.0, 1.0, 1.0)], [0, 1, 0, 0]);
    assert_eq!([axis(1.0, 3.0, 2.0), axis(1.0, 2.0, 3.0), axis(3.0, 1.0, 2.0), axis(2.0, 1.0, 3.0)], [1, 2, 0, 2]);
}

#[test]
fn offset_divides_by_the_extent_per_axis() {
    // Extents 2, 4, 8 (not 1, where `/` and `*` agree).
    let b = Aabb::new(v(1.0, -1.0, 2.0), v(3.0, 3.0, 10.0));
    assert_eq!(b.offset(v(2.5, 2.0, 4.0)), v(0.75, 0.75, 0.25));
    assert_eq!(b.offset(v(0.0, -3.0, 18.0)), v(-0.5, -0.5, 2.0));
    // Flat axes give 0, never a division by zero.
    let point = Aabb::new(Vec3::ONE, Vec3::ONE);
    assert_eq!(point.offset(v(2.0, 3.0, 4.0)), Vec3::ZERO);
}

/// pbrt-v4's `1 + 2γ₃`, in f64 and rounded once.
fn robust_far() -> f64 {
    let u = f64::from(f32::EPSILON) / 2.0;
    let gamma3 = 3.0 * u / (1.0 - 3.0 * u);
    1.0 + 2.0 * gamma3
}

#[test]
fn slab_test_entry_exit_and_clipping() {
    let b = Aabb::new(Vec3::splat(-1.0), Vec3::ONE);
    let far = |t: f64| (t * robust_far()) as f32;
    // Along +x from x = -3: in at 2, out at 4 (grown by 1 + 2γ₃ so rounding never misses).
    let (o, inv) = (v(-3.0, 0.5, 0.0), v(1.0, f32::INFINITY, f32::INFINITY));
    assert_eq!(b.intersect(o, inv, 0.0, f32::INFINITY), Some((2.0, far(4.0))));
    assert!(far(4.0) > 4.0);
    // Along -x from x = +3: the slab's near and far swap.
    assert_eq!(b.intersect(v(3.0, 0.5, 0.0), -inv, 0.0, f32::INFINITY), Some((2.0, far(4.0))));
    // The ray's interval clips both ends, and an interval of one point inside still hits.
    assert_eq!(b.intersect(o, inv, 3.0, f32::INFINITY), Some((3.0, far(4.0))));
    assert_eq!(b.intersect(o, inv, 0.0, 3.0), Some((2.0, 3.0)));
    assert_eq!(b.intersect(o, inv, 2.5, 2.5), Some((2.5, 2.5)));
    assert_eq!(b.intersect(o, inv, 0.0, 1.0), None);
    assert_eq!(b.intersect(o, inv, 5.0, 9.0), None);
    // Direction (1, 2, 0) from (-3, -3, 0): x in [2, 4], y in [1, 2]: entry 2, exit 2·(1 + 2γ₃).
    let (o, inv) = (v(-3.0, -3.0, 0.0), v(1.0, 0.5, f32::INFINITY));
    assert_eq!(b.intersect(o, inv, 0.0, f32::INFINITY), Some((2.0, far(2.0))));
    // From (-3, -6, 0): x in [2, 4], y in [2.5, 3.5].
    assert_eq!(b.intersect(v(-3.0, -6.0, 0.0), inv, 0.0, f32::INFINITY), Some((2.5, far(3.5))));
    // From (-3, -9, 0): x in [2, 4], y in [4, 5]: they meet at t = 4 only, which the
    // conservative exit keeps.
    assert_eq!(b.intersect(v(-3.0, -9.0, 0.0), inv, 0.0, f32::INFINITY), Some((4.0, far(4.0))));
    // From (-3, -10, 0): y in [4.5, 5.5] after x's [2, 4]: a miss.
    assert_eq!(b.intersect(v(-3.0, -10.0, 0.0), inv, 0.0, f32::INFINITY), None);
    // One ray's convenience form: the same numbers, and the empty box is never hit.
    let r = Ray::new(v(-3.0, 0.5, 0.0), Vec3::X);
    assert_eq!(b.intersect_ray(&r), Some((2.0, far(4.0))));
    assert_eq!(Aabb::EMPTY.intersect_ray(&r), None);
}

#[test]
fn bounding_sphere_of_a_box() {
    let s = Aabb::new(v(1.0, 2.0, 3.0), v(3.0, 6.0, 7.0)).bounding_sphere();
    assert_eq!((s.center, s.radius), (v(2.0, 4.0, 5.0), 3.0));
    assert!(Aabb::EMPTY.bounding_sphere().is_empty());
    // A sphere of radius 0 (a point) is not empty.
    assert!(!BoundingSphere { center: Vec3::ZERO, radius: 0.0 }.is_empty());
    assert!(BoundingSphere { center: Vec3::ZERO, radius: -1.0 }.is_empty());
}

fn sphere(x: f32, r: f32) -> BoundingSphere {
    BoundingSphere { center: v(x, 0.0, 0.0), radius: r }
}

#[test]
fn sphere_union_every_branch() {
    let empty = BoundingSphere { center: Vec3::ZERO, radius: -1.0 };
    assert_eq!(empty.union(sphere(3.0, 1.0)), sphere(3.0, 1.0));
    assert_eq!(sphere(3.0, 1.0).union(empty), sphere(3.0, 1.0));
    // One inside the other, touching from inside: the outer one, unchanged to the bit.
    assert_eq!(sphere(0.0, 2.0).union(sphere(1.0, 1.0)), sphere(0.0, 2.0));
    assert_eq!(sphere(1.0, 1.0).union(sphere(0.0, 2.0)), sphere(0.0, 2.0));
    // Unequal spheres side by side: from x = -1 to x = 7, centre 3, radius 4 (grown by
    // a few ulps only).
    for u in [sphere(0.0, 1.0).union(sphere(5.0, 2.0)), sphere(5.0, 2.0).union(sphere(0.0, 1.0))] {
        assert!((u.center - v(3.0, 0.0, 0.0)).length() <= 1e-6, "{u:?}");
        assert!(u.radius >= 4.0 && u.radius <= 4.0 * (1.0 + 1e-6), "{u:?}");
    }
    // Off every axis, so that no coordinate of a centre is 0: radii 1 and 2 at (1, 2, 2) and
    // (4, 6, 2), 5 apart; the union's centre is 3/5 of the way, at (2.8, 4.4, 2), radius 4.
    let (a, b) = (BoundingSphere { center: v(1.0, 2.0, 2.0), radius: 1.0 }, BoundingSphere { center: v(4.0, 6.0, 2.0), radius: 2.0 });
    for u in [a.union(b), b.union(a)] {
        assert!((u.center - v(2.8, 4.4, 2.0)).length() <= 1e-5, "{u:?}");
        assert!(u.radius >= 4.0 && u.radius <= 4.0 * (1.0 + 1e-6), "{u:?}");
    }
}

#[test]
fn sphere_intersection_hand_values() {
    // Centre (1, 2, 3), radius 3 (not 2, where r + r = r·r).
    let s = BoundingSphere { center: v(1.0, 2.0, 3.0), radius: 3.0 };
    // A direction of length 2: z = -3 + 2t crosses z = 0 and 6 at t = 1.5 and 4.5.
    let r = Ray::new(v(1.0, 2.0, -3.0), v(0.0, 0.0, 2.0));
    assert_eq!(s.intersect(&r), Some((1.5, 4.5)));
    let clipped = |t_min, t_max| s.intersect(&Ray { t_min, t_max, ..r });
    assert_eq!(clipped(2.0, f32::INFINITY), Some((2.0, 4.5)));
    assert_eq!(clipped(0.0, 3.0), Some((1.5, 3.0)));
    assert_eq!(clipped(0.0, 1.0), None);
    assert_eq!(clipped(5.0, 9.0), None);
    // Tangent at (1, 5, 3): one point, still a hit.
    assert_eq!(s.intersect(&Ray::new(v(1.0, 5.0, -3.0), Vec3::Z)), Some((6.0, 6.0)));
    assert_eq!(s.intersect(&Ray::new(v(1.0, 5.5, -3.0), Vec3::Z)), None);
    assert_eq!(BoundingSphere { radius: -1.0, ..s }.intersect(&r), None);
}
