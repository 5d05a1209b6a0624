// Runs several nodes in one thread, in lockstep: a message published by one node is delivered to every
// node that subscribes to its channel before the next input is read. Delivery is first-in first-out and
// nodes are visited in the order they were added, so a run depends only on its input: deterministic replay.
#pragma once

#include "runtime/node.hpp"

#include <deque>
#include <functional>

namespace adit::runtime {

class LockstepBus : public Sink {
 public:
  using Observer = std::function<void(const std::string& channel, const Bytes& data, std::int64_t utime)>;

  void add(Node& node) { nodes_.push_back(&node); }
  // Called for every published message (to log it, to collect results).
  void observe(Observer observer) { observers_.push_back(std::move(observer)); }

  // An input from outside (a log event): deliver it and everything it causes.
  void inject(const std::string& channel, const Bytes& data, std::int64_t utime);
  // End of input: finish nodes in order, delivering what each one publishes downstream.
  void finish();

  void publish(const std::string& channel, const Bytes& data, std::int64_t utime) override;

 private:
  struct Pending {
    std::string channel;
    Bytes data;
    std::int64_t utime;
  };
  void drain();

  std::vector<Node*> nodes_;
  std::vector<Observer> observers_;
  std::deque<Pending> queue_;
};

}  // namespace adit::runtime
