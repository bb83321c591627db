"""Reference numbers of the tree designs (the paper's hand and the algorithmic hand)."""

#: tests/design/data/papers_hand.json: the paper's three-finger hand as published, every joint
#: at its exact pose (examples/designs/hand.json: the palm slid -3 r so that its socket fits).
HAND_PARENTS = (-1, 0, 1, 2, 3, 0, 5, 6, 0, 8, 9, 10)
HAND_CHILDREN_OF_ROOT = (1, 5, 8)
HAND_TOTAL_LINK_LENGTH = 32.276748
HAND_TOLERANCE = 1e-6

#: tests/design/data/algorithmic_hand.json built by the published tree construction
#: ("siblingAzimuth": 0) with the growth direction (1/2, 1/sqrt2, 1/2): the tree's parents,
#: the tree joint of each specified joint, and the total link length (in r), without and with
#: the published extra roll.
ALGORITHMIC_HAND_PARENTS = (-1, 0, 1, 2, 3, 0, 5, 6, 7, 8, 0, 10, 11, 12, 13, 14)
ALGORITHMIC_HAND_NODES = (0, 1, 2, 3, 4, 7, 8, 9, 12, 13, 14, 15)
ALGORITHMIC_HAND_TOTAL_LINK_LENGTH = {False: 755.9963, True: 762.7118}
ALGORITHMIC_HAND_TOLERANCE = 1e-3
