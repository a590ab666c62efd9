//! Fuzz the frame decoder: any identifier and payload must give `Ok` or a typed error, never
//! a panic; and every frame that decodes must encode back to exactly the same bytes (the
//! encoding is canonical, so no two frames mean the same message).
#![no_main]

use libfuzzer_sys::fuzz_target;
use protocol::Message;

fuzz_target!(|data: &[u8]| {
    if data.len() < 2 {
        return;
    }
    // Two bytes of identifier (values above 0x7FF included), the rest is the payload
    // (lengths above 8 included).
    let id = u16::from_le_bytes([data[0], data[1]]);
    let payload = &data[2..];
    if let Ok(m) = Message::decode(id, payload) {
        let f = m.encode().expect("a decoded message encodes");
        assert_eq!(f.id.raw(), id);
        assert_eq!(f.payload(), payload);
    }
});
