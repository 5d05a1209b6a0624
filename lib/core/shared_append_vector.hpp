// An append-only sequence whose copies share the elements they hold in common.
//
// The loop closer hands every loop job a snapshot of its pose graph's edges and odometry chain, which only ever
// grow. Copied as std::vectors, each snapshot cost ~1 kB per keyframe of the whole run, and with a few jobs in
// flight that was most of a long run's memory growth. Here elements live in fixed-size chunks held by shared
// pointers: a copy costs one pointer per kChunk elements. Elements are never changed once appended; the only
// chunk that can still grow is the last, and an append copies it first when a snapshot shares it, so a copy
// never sees appends made after it. A copy may be read and destroyed on another thread while the original keeps
// appending (the chunks a copy holds are never written again).
#pragma once

#include <cstddef>
#include <iterator>
#include <memory>
#include <vector>

namespace adit {

template <typename T>
class SharedAppendVector {
 public:
  static constexpr std::size_t kChunk = 512;

  void push_back(const T& value) {
    if (size_ % kChunk == 0) {
      chunks_.push_back(std::make_shared<std::vector<T>>());
      chunks_.back()->reserve(kChunk);
    } else if (chunks_.back().use_count() > 1) {  // a snapshot shares the partial last chunk: copy it first
      auto own = std::make_shared<std::vector<T>>();
      own->reserve(kChunk);
      own->assign(chunks_.back()->begin(), chunks_.back()->begin() + static_cast<std::ptrdiff_t>(size_ % kChunk));
      chunks_.back() = std::move(own);
    }
    chunks_.back()->push_back(value);
    ++size_;
  }

  std::size_t size() const { return size_; }
  bool empty() const { return size_ == 0; }
  const T& operator[](std::size_t i) const { return (*chunks_[i / kChunk])[i % kChunk]; }
  const T& back() const { return (*this)[size_ - 1]; }

  class const_iterator {
   public:
    using iterator_category = std::forward_iterator_tag;
    using value_type = T;
    using difference_type = std::ptrdiff_t;
    using pointer = const T*;
    using reference = const T&;
    const_iterator(const SharedAppendVector* v, std::size_t i) : v_(v), i_(i) {}
    reference operator*() const { return (*v_)[i_]; }
    pointer operator->() const { return &(*v_)[i_]; }
    const_iterator& operator++() {
      ++i_;
      return *this;
    }
    bool operator==(const const_iterator& o) const { return i_ == o.i_; }
    bool operator!=(const const_iterator& o) const { return i_ != o.i_; }

   private:
    const SharedAppendVector* v_;
    std::size_t i_;
  };
  const_iterator begin() const { return {this, 0}; }
  const_iterator end() const { return {this, size_}; }

 private:
  std::vector<std::shared_ptr<std::vector<T>>> chunks_;
  std::size_t size_ = 0;
};

}  // namespace adit
