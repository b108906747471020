#include "app/input_queue.h"

#include <set>

namespace vs::viewer {

std::vector<InputEvent> InputQueue::takeFrame() {
  std::vector<InputEvent> out;
  std::set<int> buttons, keys;  // changed in this frame
  bool wheel = false, moved = false;
  while (!events_.empty()) {
    const InputEvent& e = events_.front();
    bool ends = false;
    switch (e.kind) {
      case InputEvent::Kind::Button:  // the moves before it are presented with the old buttons
        ends = !buttons.empty() || wheel || moved;
        break;
      case InputEvent::Kind::Key:
        ends = e.action != 2 && keys.count(e.code) > 0;
        break;
      case InputEvent::Kind::Move:
        ends = !buttons.empty() || wheel;
        break;
      case InputEvent::Kind::Wheel:
        ends = !buttons.empty();
        break;
      default:
        break;
    }
    if (ends && !out.empty()) break;
    if (e.kind == InputEvent::Kind::Button) buttons.insert(e.code);
    if (e.kind == InputEvent::Kind::Key && e.action != 2) keys.insert(e.code);
    if (e.kind == InputEvent::Kind::Wheel) wheel = true;
    if (e.kind == InputEvent::Kind::Move) moved = true;
    out.push_back(e);
    events_.pop_front();
  }
  return out;
}

bool MouseState::apply(const InputEvent& e) {
  if (e.kind == InputEvent::Kind::Move) {
    const bool changed = e.x != x || e.y != y;
    x = e.x;
    y = e.y;
    return changed;
  }
  if (e.kind == InputEvent::Kind::Button && e.code >= 0 && e.code < InputQueue::kButtons) {
    const bool d = e.action != 0;
    const bool changed = down[size_t(e.code)] != d;
    down[size_t(e.code)] = d;
    return changed;
  }
  return false;
}

}  // namespace vs::viewer
