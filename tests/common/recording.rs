//! Reading a recording back in a test: what the rerun debug plugin wrote to a memory sink, as
//! the viewer's chunk store.

use rerun::sink::MemorySinkStorage;
use rerun::{ChunkStore, ChunkStoreConfig, RecordingStream, StoreKind};

/// Flushes `rec` and decodes what it wrote into `storage` as the recording's chunk store.
pub fn read_back(rec: &RecordingStream, storage: &MemorySinkStorage) -> ChunkStore {
    rec.flush_blocking().expect("flush");
    let stores = ChunkStore::from_log_msgs(&ChunkStoreConfig::ALL_DISABLED, storage.take())
        .expect("decodable recording");
    stores
        .into_values()
        .find(|s| s.id().kind() == StoreKind::Recording)
        .expect("a recording store")
}
