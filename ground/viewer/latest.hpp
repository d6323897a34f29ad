#pragma once
// Latest-value and bounded-history slots filled by LCM handlers (LCM thread) and read
// by the render thread. Images use latest-value semantics: a slow display never
// queues frames and never slows message handling.
#include <cstdint>
#include <deque>
#include <mutex>
#include <optional>
#include <vector>

namespace aerie::viewer {

template <typename T>
class Latest {
 public:
  void set(T value) {
    std::lock_guard lock(m_);
    value_ = std::move(value);
    ++version_;
  }
  // Copies the value out when it changed since `seen`; updates `seen`.
  bool take_if_newer(uint64_t& seen, T& out) const {
    std::lock_guard lock(m_);
    if (version_ == seen || !value_) return false;
    out = *value_;
    seen = version_;
    return true;
  }
  std::optional<T> get() const {
    std::lock_guard lock(m_);
    return value_;
  }
  uint64_t version() const {
    std::lock_guard lock(m_);
    return version_;
  }

 private:
  mutable std::mutex m_;
  std::optional<T> value_;
  uint64_t version_ = 0;
};

// Samples (t, values...) kept for the last `capacity` entries.
template <typename T>
class History {
 public:
  explicit History(size_t capacity = 2000) : capacity_(capacity) {}
  void push(T v) {
    std::lock_guard lock(m_);
    data_.push_back(std::move(v));
    if (data_.size() > capacity_) data_.pop_front();
    ++version_;
  }
  bool snapshot_if_newer(uint64_t& seen, std::vector<T>& out) const {
    std::lock_guard lock(m_);
    if (version_ == seen) return false;
    out.assign(data_.begin(), data_.end());
    seen = version_;
    return true;
  }
  void clear() {
    std::lock_guard lock(m_);
    data_.clear();
    ++version_;
  }

 private:
  mutable std::mutex m_;
  std::deque<T> data_;
  size_t capacity_;
  uint64_t version_ = 0;
};

}  // namespace aerie::viewer
