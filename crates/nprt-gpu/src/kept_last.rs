//! The last value made for a key, kept until another key asks: the scene a model's frames
//! rasterise, the map a frame's background reads.

use std::convert::Infallible;
use std::sync::Mutex;

/// One cached value and its key, shared between threads.
pub struct KeptLast<K, V>(Mutex<Option<(K, V)>>);

impl<K, V> Default for KeptLast<K, V> {
    fn default() -> Self {
        KeptLast(Mutex::new(None))
    }
}

impl<K: PartialEq, V: Clone> KeptLast<K, V> {
    /// The value kept for `key`, or `make`'s, kept in its place.
    pub fn try_get<E>(&self, key: K, make: impl FnOnce() -> Result<V, E>) -> Result<V, E> {
        let mut kept = self.0.lock().unwrap_or_else(|e| e.into_inner());
        if let Some((k, v)) = &*kept {
            if *k == key {
                return Ok(v.clone());
            }
        }
        let v = make()?;
        *kept = Some((key, v.clone()));
        Ok(v)
    }

    /// The value kept last, whatever its key.
    pub fn kept(&self) -> Option<V> {
        let kept = self.0.lock().unwrap_or_else(|e| e.into_inner());
        kept.as_ref().map(|(_, v)| v.clone())
    }

    /// [`Self::try_get`] where making cannot fail.
    pub fn get(&self, key: K, make: impl FnOnce() -> V) -> V {
        self.try_get(key, || Ok::<_, Infallible>(make()))
            .unwrap_or_else(|e| match e {})
    }
}
