//! Writes to distinct elements of one slice from parallel tasks: the bottom-up passes over
//! a tree fill one array entry per node, and each node belongs to exactly one task.

use std::marker::PhantomData;

pub(crate) struct DisjointSlice<'a, T> {
    ptr: *mut T,
    len: usize,
    _slice: PhantomData<&'a mut [T]>,
}

// SAFETY: the slice is borrowed mutably for 'a, and `write`'s contract keeps tasks on
// distinct elements; values cross threads, hence `T: Send`.
unsafe impl<T: Send> Sync for DisjointSlice<'_, T> {}

impl<'a, T: Copy> DisjointSlice<'a, T> {
    pub(crate) fn new(slice: &'a mut [T]) -> Self {
        Self { ptr: slice.as_mut_ptr(), len: slice.len(), _slice: PhantomData }
    }

    /// Stores `v` at `i` (panics when `i` is out of range).
    ///
    /// # Safety
    /// No other call, on any thread, writes `i` while this `DisjointSlice` lives.
    pub(crate) unsafe fn write(&self, i: usize, v: T) {
        assert!(i < self.len, "index {i} out of range for a slice of {}", self.len);
        // SAFETY: in range (above); no other task touches element `i` (the caller's contract).
        unsafe { self.ptr.add(i).write(v) }
    }
}
