// A stack of plain pairs that keeps its first N in place (in the walk's own frame) and moves to the heap only
// past them. A depth-first walk seldom holds more than a few dozen pairs, and a heap block reserved per query
// cost as much as the whole of a query decided at its root pair (bench/RESULTS.md, "The walk's stack in
// place"). The best-first queue's four-ary heap keeps its pairs in one too.
#pragma once

#include <cstddef>
#include <cstring>
#include <memory>
#include <type_traits>

namespace bvhlab {

template <class T, std::size_t N>
class InlineStack {
  // Pairs are copied as bytes: into the raw room here, and over to the heap when it grows.
  static_assert(std::is_trivially_copyable_v<T> && std::is_trivially_destructible_v<T>);
  static_assert(alignof(T) <= __STDCPP_DEFAULT_NEW_ALIGNMENT__, "the heap room is aligned as new gives it");

 public:
  InlineStack() = default;
  InlineStack(const InlineStack&) = delete;  // data_ may point into this object
  InlineStack& operator=(const InlineStack&) = delete;

  [[nodiscard]] bool empty() const { return size_ == 0; }
  [[nodiscard]] std::size_t size() const { return size_; }
  [[nodiscard]] const T& front() const { return data_[0]; }
  [[nodiscard]] const T& back() const { return data_[size_ - 1]; }
  [[nodiscard]] const T& operator[](std::size_t i) const { return data_[i]; }
  [[nodiscard]] T& operator[](std::size_t i) { return data_[i]; }
  [[nodiscard]] const T* data() const { return data_; }
  [[gnu::always_inline]] void push_back(const T& item) {
    if (size_ == capacity_) [[unlikely]]
      grow();
    std::memcpy(static_cast<void*>(data_ + size_), &item, sizeof(T));
    ++size_;
  }
  [[gnu::always_inline]] void pop_back() { --size_; }

 private:
  [[gnu::noinline]] void grow() {
    auto bigger = std::make_unique_for_overwrite<std::byte[]>(2 * capacity_ * sizeof(T));
    std::memcpy(bigger.get(), static_cast<const void*>(data_), size_ * sizeof(T));
    heap_ = std::move(bigger);
    data_ = reinterpret_cast<T*>(heap_.get());
    capacity_ *= 2;
  }

  alignas(T) std::byte local_[N * sizeof(T)];
  std::unique_ptr<std::byte[]> heap_;
  T* data_ = reinterpret_cast<T*>(local_);
  std::size_t size_ = 0;
  std::size_t capacity_ = N;
};

}  // namespace bvhlab
