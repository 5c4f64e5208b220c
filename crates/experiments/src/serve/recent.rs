//! A small most-recently-used list: the editor's caches of opened materials, decoded tables
//! and renders of originals.
use std::collections::VecDeque;

/// A small most-recently-used list.
pub(super) struct Recent<K, V> {
    items: VecDeque<(K, V)>,
    capacity: usize,
}

impl<K: PartialEq, V: Clone> Recent<K, V> {
    pub(super) fn new(capacity: usize) -> Self {
        Self { items: VecDeque::new(), capacity }
    }

    pub(super) fn get(&mut self, key: &K) -> Option<V> {
        let i = self.items.iter().position(|(k, _)| k == key)?;
        let item = self.items.remove(i)?;
        let value = item.1.clone();
        self.items.push_front(item);
        Some(value)
    }

    pub(super) fn put(&mut self, key: K, value: V) {
        self.items.retain(|(k, _)| k != &key);
        self.items.push_front((key, value));
        self.items.truncate(self.capacity);
    }
}

#[cfg(test)]
mod tests {
    use super::Recent;

    #[test]
    fn the_least_recently_used_item_goes_first() {
        let mut r = Recent::new(2);
        r.put("a", 1);
        r.put("b", 2);
        assert_eq!(r.get(&"a"), Some(1));
        r.put("c", 3);
        assert_eq!(r.get(&"b"), None);
        assert_eq!((r.get(&"a"), r.get(&"c")), (Some(1), Some(3)));
        r.put("a", 4);
        assert_eq!(r.get(&"a"), Some(4));
    }
}
