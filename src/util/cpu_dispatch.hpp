// Private to src: the run-time checks behind every instruction-set-specific path of the library
// (features: FAST scores, the blur, the descriptor's rotation, the resize; optim: motion-only
// BA's pinhole residuals). Default builds target baseline x86-64, so such code is compiled
// separately (a target attribute or its own unit) and chosen with these.
#pragma once

namespace orbis::detail {

// Whether this CPU (and OS) runs AVX2; false where the check is not available. Cached.
bool cpuHasAvx2();

// Whether it runs AVX-512F (the foundation: 512-bit floating point and integer words); cached.
bool cpuHasAvx512f();

// Whether it runs AVX-512 with byte and word operations as well (AVX-512F and BW); cached.
bool cpuHasAvx512bw();

}  // namespace orbis::detail
