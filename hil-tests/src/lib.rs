//! Firmware-in-the-loop integration tests (in `tests/`): the `wisse3d` walker with both ankle
//! nodes' firmware on the simulated CAN bus (`sil::FirmwareInTheLoop`), nominally and
//! under bus and sensor faults. See `docs/sil.md`. The library itself is empty.
