// Private to src/features: the one run-time check behind every AVX2 path of the module (the
// descriptor's rotation, the blur, the FAST score map). Default builds target baseline x86-64,
// so AVX2 code is compiled separately (a target attribute or its own -mavx2 unit) and chosen here.
#pragma once

namespace orbis::detail {

// Whether this CPU (and OS) runs AVX2; false where the check is not available. Cached.
bool cpuHasAvx2();

// Whether this CPU (and OS) runs AVX-512 with byte and word operations (AVX-512BW); cached.
bool cpuHasAvx512bw();

}  // namespace orbis::detail
