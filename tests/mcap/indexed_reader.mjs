// What the MCAP tests share: the independent readers (@mcap/core's McapIndexedReader with
// @foxglove/wasm-zstd's zstd, as Foxglove reads), loaded or the test skipped (exit 77), and a
// recording opened through its index.
import { open } from "node:fs/promises";

// The readers, or exit 77 (skipped) naming `test` when node_modules lacks them.
export async function loadReaders(test) {
  try {
    const { McapIndexedReader } = await import("@mcap/core");
    const zstd = (await import("@foxglove/wasm-zstd")).default;
    await zstd.isLoaded;
    return { McapIndexedReader, zstd };
  } catch {
    console.error(`${test}: @mcap/core or @foxglove/wasm-zstd is not installed (scripts/install-deps.sh): skipped`);
    process.exit(77);
  }
}

// `path` opened with the indexed reader (zstd chunks decompressed); close() when done.
export async function openIndexed({ McapIndexedReader, zstd }, path) {
  const file = await open(path, "r");
  const reader = await McapIndexedReader.Initialize({
    readable: {
      size: async () => BigInt((await file.stat()).size),
      read: async (offset, size) => {
        const buf = Buffer.alloc(Number(size));
        const { bytesRead } = await file.read(buf, 0, buf.length, Number(offset));
        if (bytesRead !== buf.length) throw new Error(`short read at ${offset}`);
        return new Uint8Array(buf.buffer, buf.byteOffset, buf.byteLength);
      },
    },
    decompressHandlers: { zstd: (data, size) => zstd.decompress(data, Number(size)) },
  });
  return { reader, close: () => file.close() };
}
