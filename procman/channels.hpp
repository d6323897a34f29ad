#pragma once
// Channel names of libbot2's bot_procman protocol, so that libbot2 sheriffs and
// deputies interoperate with Aerie's, and of Aerie's keyed orders.
namespace aerie::procman {

inline constexpr const char* kInfoChannel = "PMD_INFO2";       // bot_procman.info2_t, deputy -> sheriff
inline constexpr const char* kOrdersChannel = "PMD_ORDERS2";   // bot_procman.orders2_t, sheriff -> deputy
inline constexpr const char* kPrintfChannel = "PMD_PRINTF";    // bot_procman.printf_t, deputy -> sheriff
inline constexpr const char* kDiscoverChannel = "PMD_DISCOVER";  // bot_procman.discovery_t, both ways
// Aerie's keyed mode (not libbot2's): orders2_t bytes with a sender id, counter and tag
// (procman/orders_auth.hpp), sheriff -> deputy.
inline constexpr const char* kSealedOrdersChannel = "PMD_ORDERS2_SEALED";

}  // namespace aerie::procman
