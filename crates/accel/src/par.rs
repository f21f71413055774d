//! A small helper for parallel builders: a slice that tasks running at the same time write
//! at positions no two of them share.

use std::marker::PhantomData;

/// A mutable slice shared by parallel tasks (`rayon::join`) that read and write it at
/// disjoint positions: each position belongs to one task at a time, the owner of a tree node
/// in the builders. Bounds are checked; only the disjointness is the caller's promise, which
/// is what makes [`DisjointSlice::write`] and [`DisjointSlice::get`] `unsafe`. Used where
/// the positions a task owns are not one range (tree nodes indexed by id, not by subtree),
/// so that `split_at_mut` cannot hand them out.
pub(crate) struct DisjointSlice<'a, T> {
    ptr: *mut T,
    len: usize,
    _borrow: PhantomData<&'a mut [T]>,
}

// SAFETY: the slice is borrowed mutably for 'a, so nothing else touches it; values of `T`
// are moved between threads (Send) and seen from several (Sync), as with `&mut [T]` shared.
unsafe impl<T: Send> Send for DisjointSlice<'_, T> {}
// SAFETY: as above; concurrent access to one position is excluded by the callers' promise.
unsafe impl<T: Send + Sync> Sync for DisjointSlice<'_, T> {}

impl<'a, T: Copy> DisjointSlice<'a, T> {
    pub(crate) fn new(slice: &'a mut [T]) -> Self {
        Self { ptr: slice.as_mut_ptr(), len: slice.len(), _borrow: PhantomData }
    }

    /// Stores `v` at `i`.
    ///
    /// # Safety
    /// No other task reads or writes position `i` while this runs.
    ///
    /// # Panics
    /// If `i` is out of bounds.
    #[inline]
    pub(crate) unsafe fn write(&self, i: usize, v: T) {
        assert!(i < self.len, "DisjointSlice: index {i} out of bounds ({})", self.len);
        // SAFETY: in bounds (checked), the slice is borrowed for 'a, and the caller excludes
        // concurrent access to `i`.
        unsafe { self.ptr.add(i).write(v) }
    }

    /// The value at `i`.
    ///
    /// # Safety
    /// No other task writes position `i` while this runs, and a write to `i` by another task
    /// happened before it (as a `rayon::join` that has returned orders its closures' writes).
    ///
    /// # Panics
    /// If `i` is out of bounds.
    #[inline]
    pub(crate) unsafe fn get(&self, i: usize) -> T {
        assert!(i < self.len, "DisjointSlice: index {i} out of bounds ({})", self.len);
        // SAFETY: in bounds (checked); no concurrent write, by the caller's promise.
        unsafe { self.ptr.add(i).read() }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tasks_write_their_own_halves() {
        let mut v = vec![0u32; 1000];
        let s = DisjointSlice::new(&mut v);
        let s = &s;
        rayon::join(
            // SAFETY: the first task owns the even positions, the second the odd ones.
            || (0..1000).step_by(2).for_each(|i| unsafe { s.write(i, i as u32) }),
            || (1..1000).step_by(2).for_each(|i| unsafe { s.write(i, 2 * i as u32) }),
        );
        // SAFETY: both tasks have finished.
        assert_eq!(unsafe { s.get(3) }, 6);
        assert!(v.iter().enumerate().all(|(i, &x)| x as usize == if i % 2 == 0 { i } else { 2 * i }));
    }

    /// One past the end panics, for `write` and `get`, rather than touching memory outside
    /// the slice: the last element is written and read back, its neighbour left alone.
    #[test]
    fn accesses_past_the_end_panic() {
        let mut backing = vec![7u32; 6];
        {
            let s = DisjointSlice::new(&mut backing[..5]);
            // SAFETY: one writer.
            unsafe { s.write(4, 9) };
            // SAFETY: as above; out of range, so it must panic.
            let r = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| unsafe { s.write(5, 1) }));
            assert!(r.is_err(), "index 5 of a slice of 5 must panic");
            // SAFETY: no writer left.
            assert_eq!(unsafe { s.get(4) }, 9);
            // SAFETY: as above; out of range, so it must panic.
            let r = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| unsafe { s.get(5) }));
            assert!(r.is_err(), "reading index 5 of a slice of 5 must panic");
        }
        assert_eq!(backing, [7, 7, 7, 7, 9, 7], "only element 4 changes");
    }
}
