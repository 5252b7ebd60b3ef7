#pragma once
// The flags that pick a sequence (dataset folder or synthetic scene), shared by nidevo-run and
// nidevo-client.
#include "frame_loader.hpp"

namespace nidevo::cli {

SequenceSource sequenceSourceFromFlags();

}  // namespace nidevo::cli
