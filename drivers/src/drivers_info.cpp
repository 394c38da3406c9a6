// Keeps dockcore_drivers a real library even before its first driver; the drivers live beside this file.
namespace dockcore::drivers {
const char* drivers_build_id() { return "dockcore-drivers"; }
}  // namespace dockcore::drivers
