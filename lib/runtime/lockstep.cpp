#include "runtime/lockstep.hpp"

namespace adit::runtime {

void LockstepBus::publish(const std::string& channel, const Bytes& data, std::int64_t utime) {
  for (auto& observer : observers_) observer(channel, data, utime);
  queue_.push_back({channel, data, utime});
}

void LockstepBus::inject(const std::string& channel, const Bytes& data, std::int64_t utime) {
  queue_.push_back({channel, data, utime});
  drain();
}

void LockstepBus::finish() {
  for (Node* node : nodes_) {
    node->finish(*this);
    drain();
  }
}

void LockstepBus::drain() {
  while (!queue_.empty()) {
    const Pending message = std::move(queue_.front());
    queue_.pop_front();
    for (Node* node : nodes_)
      if (node->isInput(message.channel)) node->deliver(message.channel, message.data.data(), message.data.size(), *this);
  }
}

}  // namespace adit::runtime
