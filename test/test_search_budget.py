"""A search the planner sizes itself keeps to the plan's budget (SearchBudget.within):
an alternative's walk of 1,000 nodes searches at most the PlannerOptions.budget a user
set, and a time limit given on either side holds."""

from __future__ import annotations

from ltl_human_motion.planning.astar import SearchBudget


def test_the_smaller_node_limit_holds_and_the_rest_is_kept():
    own = SearchBudget(1000, at_goal_nodes=300, idle_nodes=50)
    capped = own.within(SearchBudget(40))
    assert (capped.max_nodes, capped.at_goal_nodes, capped.idle_nodes) == (40, 300, 50)
    assert own.within(SearchBudget()) == own           # the default plan budget is larger


def test_a_time_limit_on_either_side_holds():
    assert SearchBudget(10).within(SearchBudget(100, max_seconds=2.0)).max_seconds == 2.0
    assert SearchBudget(10, max_seconds=1.0).within(SearchBudget(100)).max_seconds == 1.0
    assert SearchBudget(10, max_seconds=3.0).within(
        SearchBudget(100, max_seconds=2.0)).max_seconds == 2.0
    assert SearchBudget(10).within(SearchBudget(100)).max_seconds is None
