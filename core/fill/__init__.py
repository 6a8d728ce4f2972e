"""Fill and extend (issue 15): heal a painted region, remove an object, uncrop."""
