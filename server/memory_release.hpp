#pragma once
// Returns the heap memory the allocator keeps after sessions end to the operating system.

namespace nidevo::server {

// glibc keeps freed session buffers (images, FFT planes, gRPC messages) in its per-thread arenas,
// so after a burst of sessions the resident size stays near its peak. malloc_trim gives the free
// pages back. It walks every arena under its lock, so the service calls it only when no session
// is open (nobody waits on an allocation then). True when the allocator supports it (glibc).
bool releaseFreedMemory();

}  // namespace nidevo::server
