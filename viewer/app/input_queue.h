// The window's input events in the order they happened (GL-free, so the rule is tested without a
// display). The window's GLFW callbacks only push here; each frame takes the longest prefix that
// can be presented as one ImGui frame without losing anything (ImGui 1.86 sees states, not
// events): a key that changes twice, a button change after a move or another button change (a
// drag's moves are seen with the button still down), a move after a button change (the click
// happens where it was pressed) or a wheel notch after a button change ends the frame's share,
// and the rest waits for the next frame (drawn at once). So a click shorter than a frame, a double click, a
// key tapped twice and every wheel notch reach the views, in order.
#pragma once
#include <array>
#include <cstddef>
#include <deque>
#include <vector>

namespace vs::viewer {

struct InputEvent {
  enum class Kind { Move, Button, Wheel, Key, Char, Focus, Enter };
  Kind kind = Kind::Move;
  double x = 0, y = 0;  // Move: window pixels; Wheel: offsets (x, y)
  int code = 0;         // Button: button; Key: key; Char: codepoint; Focus/Enter: 1 or 0
  int action = 0;       // Button/Key: 1 press, 0 release, 2 repeat
  int mods = 0;
  int scancode = 0;
  double time = 0;  // seconds (steady clock) when the window received it, for latency figures
};

class InputQueue {
 public:
  static constexpr int kButtons = 5;
  void push(const InputEvent& e) { events_.push_back(e); }
  bool empty() const { return events_.empty(); }
  size_t size() const { return events_.size(); }
  // Removes and returns this frame's share (at least one event when any are queued).
  std::vector<InputEvent> takeFrame();
  void clear() { events_.clear(); }

 private:
  std::deque<InputEvent> events_;
};

// The mouse as the events so far leave it (what the frame presents to ImGui).
struct MouseState {
  double x = -1e30, y = -1e30;  // unknown until the first move
  std::array<bool, InputQueue::kButtons> down{};
  // Applies one event; returns true when it changed the state.
  bool apply(const InputEvent& e);
};

}  // namespace vs::viewer
