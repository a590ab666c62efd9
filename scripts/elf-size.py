#!/usr/bin/env python3
"""Flash and static RAM of a 32-bit ARM ELF, from its section headers (no binutils needed).

Usage: elf-size.py ELF [--flash-budget BYTES] [--ram-budget BYTES]
Flash: every allocated section with a load image (vector table, text, rodata, data).
RAM: every allocated section at a RAM address (data, bss, uninit). Exits 1 over budget.
"""
import argparse
import struct
import sys

SHF_ALLOC = 0x2
SHT_NOBITS = 8


def sections(path):
    with open(path, "rb") as f:
        data = f.read()
    if data[:4] != b"\x7fELF" or data[4] != 1:
        sys.exit(f"{path}: not a 32-bit ELF")
    shoff, = struct.unpack_from("<I", data, 0x20)
    shentsize, shnum, shstrndx = struct.unpack_from("<HHH", data, 0x2E)
    hdrs = [struct.unpack_from("<IIIIIIIIII", data, shoff + i * shentsize) for i in range(shnum)]
    strtab_off = hdrs[shstrndx][4]

    def name(off):
        end = data.index(b"\0", strtab_off + off)
        return data[strtab_off + off:end].decode()

    for h in hdrs:
        sh_name, sh_type, sh_flags, sh_addr, _off, sh_size = h[:6]
        yield name(sh_name), sh_type, sh_flags, sh_addr, sh_size


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("elf")
    ap.add_argument("--flash-budget", type=int)
    ap.add_argument("--ram-budget", type=int)
    a = ap.parse_args()
    flash = ram = 0
    rows = []
    for name, typ, flags, addr, size in sections(a.elf):
        if not flags & SHF_ALLOC or size == 0:
            continue
        in_ram = 0x20000000 <= addr < 0x40000000
        if typ != SHT_NOBITS:
            flash += size
        if in_ram:
            ram += size
        rows.append((name, addr, size))
    for name, addr, size in rows:
        print(f"  {name:<16} 0x{addr:08x} {size:>8} B")
    print(f"flash {flash} B ({flash / 1024:.1f} KiB), static RAM {ram} B ({ram / 1024:.1f} KiB)")
    over = False
    if a.flash_budget is not None and flash > a.flash_budget:
        print(f"FLASH OVER BUDGET: {flash} > {a.flash_budget}")
        over = True
    if a.ram_budget is not None and ram > a.ram_budget:
        print(f"RAM OVER BUDGET: {ram} > {a.ram_budget}")
        over = True
    sys.exit(1 if over else 0)


if __name__ == "__main__":
    main()
