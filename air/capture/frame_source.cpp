#include "air/capture/frame_source.hpp"

namespace aerie::capture {

void FrameSource::seek(int64_t index) {
  Frame f;
  for (int64_t i = 0; i < index; ++i) {
    try {
      if (!next(f)) return;
    } catch (const FrameError&) {
      // an unreadable frame before the start does not matter
    }
  }
}

}  // namespace aerie::capture
