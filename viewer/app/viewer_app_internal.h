// What viewer_app.cpp and its parts (stylus_pick.cpp, viewer_session.cpp) share.
#pragma once

namespace vs::viewer {

inline constexpr const char* kPhantomSource = "phantom:head";  // load's name of the built-in head phantom
inline constexpr const char* kEditedTf = "edited";             // the session's name of an edited transfer function

}  // namespace vs::viewer
