#pragma once
// (being written for issue 26)
