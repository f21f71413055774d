use raylab_core::{Aabb, Vec3};

/// One BVH node, 32 bytes (two per 64-byte cache line).
///
/// Interior (`count == 0`): children at `left_first` and `left_first + 1`.
/// Leaf (`count > 0`): primitives `indices[left_first .. left_first + count]`.
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C)]
pub struct BvhNode {
    pub min: [f32; 3],   // 12 bytes
    pub left_first: u32, //  4
    pub max: [f32; 3],   // 12
    pub count: u32,      //  4 -> 32
}

const _: () = assert!(std::mem::size_of::<BvhNode>() == 32);

impl BvhNode {
    pub fn leaf(bounds: Aabb, first: u32, count: u32) -> Self {
        debug_assert!(count > 0);
        Self { min: bounds.min.to_array(), left_first: first, max: bounds.max.to_array(), count }
    }

    pub fn interior(bounds: Aabb, left: u32) -> Self {
        Self { min: bounds.min.to_array(), left_first: left, max: bounds.max.to_array(), count: 0 }
    }

    #[inline]
    pub fn is_leaf(&self) -> bool {
        self.count > 0
    }

    #[inline]
    pub fn bounds(&self) -> Aabb {
        Aabb { min: Vec3::from_array(self.min), max: Vec3::from_array(self.max) }
    }
}
